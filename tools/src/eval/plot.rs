//! Small PNG line plots (eval and density views) on `plotters`. Text is drawn with ab_glyph from
//! DejaVu Sans loaded at run time, so no fontconfig/freetype is needed and no font is vendored.

use anyhow::{anyhow, Result};
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

/// Debian package `fonts-dejavu-core` (installed by `scripts/setup`).
pub const FONT_PATH: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
const FONT: &str = "fovea-sans";
const SIZE: (u32, u32) = (900, 600);
/// Series of at most this many points get a marker at each.
const MARKED_POINTS: usize = 16;
const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(90, 90, 90),
];

/// One line: `points` are (x, y); non-finite points (and y ≤ 0 on a log axis) are left out.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// Registers the font with plotters once per process; later calls return the first outcome.
fn ensure_font() -> Result<()> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            // plotters keeps fonts in a process-wide table of 'static slices; this runs once.
            let bytes: &'static [u8] = Box::leak(read_font(FONT_PATH)?.into_boxed_slice());
            plotters::style::register_font(FONT, FontStyle::Normal, bytes)
                .map_err(|_| format!("plot font {FONT_PATH} is not a valid TrueType font"))
        })
        .clone()
        .map_err(|e| anyhow!(e))
}

fn read_font(path: &str) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| {
        format!("plot font {path} cannot be read ({e}); install the Debian package fonts-dejavu-core (scripts/setup does)")
    })
}

/// Writes a 900×600 PNG line plot with axis labels and a legend; `log_y` makes the y axis
/// logarithmic (base 10).
pub fn line_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    log_y: bool,
) -> Result<()> {
    ensure_font()?;
    let kept: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .copied()
                .filter(|&(x, y)| x.is_finite() && y.is_finite() && (!log_y || y > 0.0))
                .collect()
        })
        .collect();
    let x = padded_range(kept.iter().flatten().map(|p| p.0), false);
    let (y0, y1) = padded_range(kept.iter().flatten().map(|p| p.1), log_y);
    let labels = [title, x_label, y_label];
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    let drawn = if log_y {
        draw(&mut rgb, labels, x, (y0..y1).log_scale(), series, &kept)
    } else {
        draw(&mut rgb, labels, x, y0..y1, series, &kept)
    };
    drawn.map_err(|e| anyhow!("drawing plot {}: {e}", path.display()))?;
    crate::output::write_image(path, SIZE.0, SIZE.1, &rgb, image::ExtendedColorType::Rgb8)
}

/// The drawing, generic over the y axis (plotters gives linear and log axes different types).
fn draw<Y>(
    rgb: &mut [u8],
    [title, x_label, y_label]: [&str; 3],
    (x0, x1): (f64, f64),
    y_axis: Y,
    series: &[Series],
    kept: &[Vec<(f64, f64)>],
) -> Result<(), Box<dyn std::error::Error>>
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let root = BitMapBackend::with_buffer(rgb, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, (FONT, 22))
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(76)
        .build_cartesian_2d(x0..x1, y_axis)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 17))
        .x_label_formatter(&|v| short_number(*v))
        .y_label_formatter(&|v| short_number(*v))
        .draw()
        .map_err(|e| e.to_string())?;
    for (i, (s, points)) in series.iter().zip(kept).enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        chart
            .draw_series(LineSeries::new(
                points.iter().copied(),
                colour.stroke_width(2),
            ))
            .map_err(|e| e.to_string())?
            .label(s.label.as_str())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], colour.stroke_width(2)));
        // A few measured points (one per budget, say) are marked: a single one draws no line.
        if points.len() <= MARKED_POINTS {
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(|e| e.to_string())?;
        }
    }
    chart
        .configure_series_labels()
        .position(emptiest_corner(kept, (x0, x1)))
        .label_font((FONT, 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())?;
    Ok(())
}

/// The corner of the plot whose quarter holds the fewest points, for the legend (which would
/// hide what it covers).
fn emptiest_corner(kept: &[Vec<(f64, f64)>], (x0, x1): (f64, f64)) -> SeriesLabelPosition {
    let points: Vec<(f64, f64)> = kept.iter().flatten().copied().collect();
    let (mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY);
    for &(_, y) in &points {
        (y0, y1) = (y0.min(y), y1.max(y));
    }
    let (xm, ym) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let count = |right: bool, upper: bool| {
        points
            .iter()
            .filter(|&&(x, y)| (x >= xm) == right && (y >= ym) == upper)
            .count()
    };
    [
        (SeriesLabelPosition::UpperRight, count(true, true)),
        (SeriesLabelPosition::UpperLeft, count(false, true)),
        (SeriesLabelPosition::LowerRight, count(true, false)),
        (SeriesLabelPosition::LowerLeft, count(false, false)),
    ]
    .into_iter()
    .min_by_key(|(_, n)| *n)
    .map_or(SeriesLabelPosition::UpperRight, |(p, _)| p)
}

/// Data range with a small margin; never empty (plotters needs lo < hi), positive on log axes.
fn padded_range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if !(lo.is_finite() && hi.is_finite()) {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        // Half a decade of headroom each side keeps lines off the frame.
        (lo / 3.0, hi * 3.0)
    } else if hi > lo {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    } else {
        (lo - 0.5 - lo.abs() * 0.1, hi + 0.5 + hi.abs() * 0.1)
    }
}

/// Tick labels: at most 3 significant digits, no trailing zeros.
fn short_number(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.1e}");
    }
    let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_a_png_of_the_promised_size() {
        let dir = std::env::temp_dir().join(format!("fovea-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let series = [
            Series {
                label: "rising".into(),
                points: (1..20).map(|i| (i as f64, (i * i) as f64)).collect(),
            },
            Series {
                label: "flat with a zero".into(),
                points: vec![(0.0, 0.0), (5.0, 2.0), (19.0, 2.0)],
            },
        ];
        for log_y in [false, true] {
            let path = dir.join(format!("plot_{log_y}.png"));
            line_plot(&path, "test", "x", "y", &series, log_y).unwrap();
            let img = image::open(&path).unwrap();
            assert_eq!((img.width(), img.height()), SIZE);
            // Something besides the white background was drawn.
            assert!(img.to_rgb8().pixels().any(|p| p.0 == [31, 119, 180]));
        }
        // An empty plot still has valid ranges.
        line_plot(&dir.join("empty.png"), "empty", "x", "y", &[], true).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_missing_font_names_the_file_and_the_package() {
        let err = read_font("/no/such/DejaVuSans.ttf").unwrap_err();
        assert!(
            err.contains("/no/such/DejaVuSans.ttf") && err.contains("fonts-dejavu-core"),
            "{err}"
        );
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(short_number(0.015625), "0.0156");
        assert_eq!(short_number(64.0), "64");
        assert_eq!(short_number(2.5), "2.5");
        assert_eq!(short_number(1e-5), "1.0e-5");
    }
}
