//! `fovea eval`: quality of a rendered frame against a reference, whole-frame and per ring of
//! eccentricity around the gaze → `DIR/eval.json` + `DIR/eval.png`. RMSE/PSNR/SSIM on the values
//! given (linear EXR, or PNG as it is), FLIP on the images as displayed (EXR through the
//! project's tone curve, PNG as it is) at the headset's pixels per degree.

use crate::eval::flip::flip_map;
use crate::eval::metrics::{
    add_flip, add_flip_rings, evaluate, evaluate_rings, CoordinateRing, Evaluation, Rings,
};
use crate::eval::plot::{line_plot, Series};
use crate::output::{prepare_output_dir, read_exr, tonemap_preview, write_json};
use anyhow::{bail, Context, Result};
use fovea_renderer::passes::tonemap::ToneCurve;
use glam::Vec2;
use serde::Serialize;
use std::path::{Path, PathBuf};

pub struct EvalArgs<'a> {
    pub reference: &'a Path,
    pub test: &'a Path,
    /// `X,Y` in pixels of the images (y down), or `center`.
    pub gaze: &'a str,
    pub rings: usize,
    pub out: &'a Path,
    /// Also ring by true eccentricity (degrees) through this headset's left-eye FOV.
    pub headset: Option<&'a str>,
    /// FLIP's pixels per degree (default: the image across the `--headset` eye's horizontal FOV,
    /// the FOVE 0's without one).
    pub ppd: Option<f32>,
}

/// An input image: values for RMSE/PSNR/SSIM and the picture as displayed (for FLIP).
struct Input {
    width: u32,
    height: u32,
    values: Vec<[f32; 4]>,
    displayed: Vec<u8>,
    png: bool,
}

/// Rings of true eccentricity: equal widths in degrees from the gaze direction out to the
/// farthest corner's (the images are taken to fill the eye's FOV).
#[derive(Serialize)]
struct TrueEccentricity {
    headset: String,
    e_max_deg: f64,
    /// `inner` / `outer` in degrees.
    rings: Vec<CoordinateRing>,
}

/// eval.json: the inputs, then the metrics (field order kept as written).
#[derive(Serialize)]
struct Report<'a> {
    reference: String,
    test: String,
    /// exr (linear; FLIP on the tonemapped image) or png (as it is).
    inputs: &'static str,
    flip_ppd: f32,
    #[serde(flatten)]
    eval: &'a Evaluation,
    #[serde(skip_serializing_if = "Option::is_none")]
    true_eccentricity: Option<TrueEccentricity>,
}

/// The most rings `--rings` takes (eval.json holds one entry per ring, and each ring gets a
/// per-pixel mask).
pub const MAX_RINGS: usize = 1000;

/// `--rings` of `fovea eval` and `fovea quality`: 1 to `MAX_RINGS`, and (once the image size is
/// known) at most the image's half-diagonal in pixels, so that every ring is at least one pixel
/// wide (the rings reach the farthest corner, which is at least that far from any gaze).
pub fn check_rings(rings: usize, size: Option<(u32, u32)>) -> Result<()> {
    if !(1..=MAX_RINGS).contains(&rings) {
        bail!("--rings {rings} must be in 1..={MAX_RINGS}");
    }
    if let Some((w, h)) = size {
        let half_diagonal = 0.5 * (w as f64).hypot(h as f64);
        let most = (half_diagonal.floor() as usize).max(1);
        if rings > most {
            bail!("--rings {rings}: a {w}×{h} image has room for at most {most} rings of at least one pixel (its half-diagonal is {half_diagonal:.1} px)");
        }
    }
    Ok(())
}

pub fn run(args: &EvalArgs) -> Result<()> {
    check_rings(args.rings, None)?;
    let reference_input = read_input(args.reference)?;
    let test_input = read_input(args.test)?;
    if reference_input.png != test_input.png {
        bail!("--reference and --test must both be linear EXR or both PNG (as displayed); got {} and {}", args.reference.display(), args.test.display());
    }
    let (w, h, reference) = (
        reference_input.width,
        reference_input.height,
        &reference_input.values,
    );
    let (tw, th, test) = (test_input.width, test_input.height, &test_input.values);
    if (tw, th) != (w, h) {
        bail!(
            "{} is {tw}×{th} but the reference {} is {w}×{h}; both must have the same size",
            args.test.display(),
            args.reference.display()
        );
    }
    check_rings(args.rings, Some((w, h)))?;
    let gaze = parse_gaze(args.gaze, w, h)?;
    let hmd = match args.headset {
        Some(name) => Some(
            fovea_hal::HmdDescription::resolve(name)
                .with_context(|| format!("--headset {name}"))?,
        ),
        None => None,
    };
    let ppd = flip_ppd(args.ppd, hmd.as_ref(), w)?;
    let _out_dir = prepare_output_dir(args.out)?;
    let flip = flip_map(&reference_input.displayed, &test_input.displayed, w, h, ppd);
    let mut eval = evaluate(reference, test, w, h, gaze, args.rings);
    add_flip(&mut eval, &flip);
    let true_eccentricity = hmd.map(|hmd| {
        let fov = crate::render_profile::fov_tangents(&hmd.eye(fovea_hal::Eye::Left).fov);
        let axis = fovea_renderer::sampling::HeadsetAxis::new(fov, glam::UVec2::new(w, h), gaze);
        let degrees: Vec<f64> = (0..h)
            .flat_map(|y| (0..w).map(move |x| Vec2::new(x as f32 + 0.5, y as f32 + 0.5)))
            .map(|p| axis.eccentricity(p - gaze) as f64)
            .collect();
        let rings = Rings::from_coordinates(w, gaze, &degrees, axis.e_max as f64, args.rings);
        let mut found = evaluate_rings(reference, test, w, h, &rings);
        add_flip_rings(&mut found, &rings, &flip);
        TrueEccentricity {
            headset: hmd.id.clone(),
            e_max_deg: axis.e_max as f64,
            rings: found,
        }
    });

    let json_path = args.out.join("eval.json");
    let report = Report {
        reference: args.reference.display().to_string(),
        test: args.test.display().to_string(),
        inputs: if reference_input.png { "png" } else { "exr" },
        flip_ppd: ppd,
        eval: &eval,
        true_eccentricity,
    };
    write_json(&json_path, &report)?;
    write_plot(&args.out.join("eval.png"), &eval)?;

    let f = &eval.frame;
    let inner = eval.rings.first().and_then(|r| r.metrics.rmse);
    let outer = eval.rings.last().and_then(|r| r.metrics.rmse);
    let fmt = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{v:.4}"));
    println!(
        "eval {}×{} gaze ({:.1}, {:.1}): RMSE {} PSNR {} dB SSIM {} FLIP {} ({ppd:.1} px/°); RMSE innermost ring {} outermost {} → {}",
        w,
        h,
        gaze.x,
        gaze.y,
        fmt(f.rmse),
        f.psnr.map_or("n/a".to_string(), |v| format!("{v:.2}")),
        fmt(f.ssim),
        fmt(f.flip),
        fmt(inner),
        fmt(outer),
        json_path.display()
    );
    Ok(())
}

/// A PNG as it is (values in 0…1, no tone curve) or a linear EXR (tonemapped for FLIP).
fn read_input(path: &Path) -> Result<Input> {
    let png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if png {
        let (width, height, displayed) =
            fovea_stage::decode::read_rgba8(path, fovea_stage::decode::MAX_IMAGE_PIXELS, None)?;
        let values = displayed
            .chunks_exact(4)
            .map(|p| [p[0], p[1], p[2], p[3]].map(|c| c as f32 / 255.0))
            .collect();
        return Ok(Input {
            width,
            height,
            values,
            displayed,
            png,
        });
    }
    let (width, height, values) = read_checked(path)?;
    let displayed = tonemap_preview(&values, 1.0, ToneCurve::Aces);
    Ok(Input {
        width,
        height,
        values,
        displayed,
        png,
    })
}

/// `--ppd`, or the image stretched over the headset eye's horizontal FOV.
fn flip_ppd(
    given: Option<f32>,
    hmd: Option<&fovea_hal::HmdDescription>,
    width: u32,
) -> Result<f32> {
    if let Some(ppd) = given {
        if !(ppd.is_finite() && ppd > 0.0 && ppd <= 1000.0) {
            bail!("--ppd {ppd} must be in (0, 1000] pixels per degree");
        }
        return Ok(ppd);
    }
    let fove0 = fovea_hal::HmdDescription::fove0();
    Ok(crate::eval::flip::headset_ppd(hmd.unwrap_or(&fove0), width))
}

/// Reads an EXR, refusing NaN and infinite pixels (they would silently poison every mean).
fn read_checked(path: &Path) -> Result<(u32, u32, Vec<[f32; 4]>)> {
    let (w, h, pixels) = read_exr(path)?;
    let bad = |p: &[f32; 4]| p[..3].iter().copied().find(|c| !c.is_finite());
    if let Some((i, c)) = pixels
        .iter()
        .enumerate()
        .find_map(|(i, p)| Some((i, bad(p)?)))
    {
        bail!(
            "{} has a non-finite value ({c}) at pixel ({}, {})",
            path.display(),
            i as u32 % w,
            i as u32 / w
        );
    }
    Ok((w, h, pixels))
}

/// `X,Y` (finite, inside the image, edges included) or `center`.
fn parse_gaze(spec: &str, width: u32, height: u32) -> Result<Vec2> {
    let t = spec.trim();
    if t.eq_ignore_ascii_case("center") || t.eq_ignore_ascii_case("centre") {
        return Ok(Vec2::new(width as f32, height as f32) * 0.5);
    }
    let parsed = t
        .split_once(',')
        .and_then(|(x, y)| Some(Vec2::new(x.trim().parse().ok()?, y.trim().parse().ok()?)));
    let Some(g) = parsed.filter(|g| g.is_finite()) else {
        bail!("--gaze '{spec}': expected X,Y as two finite pixel coordinates (e.g. 160,180) or center");
    };
    if g.x < 0.0 || g.y < 0.0 || g.x > width as f32 || g.y > height as f32 {
        bail!("--gaze '{spec}' lies outside the {width}×{height} image");
    }
    Ok(g)
}

fn write_plot(path: &Path, eval: &Evaluation) -> Result<()> {
    let per_ring =
        |label: &str, value: &dyn Fn(&crate::eval::metrics::Metrics) -> Option<f64>| Series {
            label: label.into(),
            points: eval
                .rings
                .iter()
                .filter_map(|r| Some((0.5 * (r.ecc_inner + r.ecc_outer), value(&r.metrics)?)))
                .collect(),
        };
    let series = [
        per_ring("RMSE (linear RGB)", &|m| m.rmse),
        per_ring("SSIM (luma)", &|m| m.ssim),
    ];
    let title = format!(
        "Error per eccentricity ring, gaze ({:.0}, {:.0})",
        eval.gaze[0], eval.gaze[1]
    );
    line_plot(
        path,
        &title,
        "normalised eccentricity (r / r_max · 80)",
        "RMSE, SSIM",
        &series,
        false,
    )
}

// `fovea eval` (its help is the variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct EvalCommand {
    /// Reference: a linear EXR (e.g. from `fovea reference`) or a PNG (taken as displayed).
    #[arg(long)]
    pub reference: PathBuf,
    /// Frame to evaluate, of the reference's size and kind (e.g. `fovea render --exr`, or its PNG).
    #[arg(long)]
    pub test: PathBuf,
    /// Gaze point X,Y in image pixels (y down), or center; rings are centred on it.
    #[arg(long)]
    pub gaze: String,
    /// Equal-width rings from the gaze out to the farthest image corner.
    #[arg(long, default_value_t = 20)]
    pub rings: usize,
    /// Output folder for eval.json and eval.png (must hold only fovea's own outputs).
    #[arg(long, default_value = "out/eval")]
    pub out: PathBuf,
    /// Also report rings of true eccentricity (degrees) through this headset's left-eye FOV
    /// (eval.json `true_eccentricity`).
    #[arg(long)]
    pub headset: Option<String>,
    /// FLIP's pixels per degree (default: the image width over the --headset eye's
    /// horizontal FOV, the FOVE 0's without --headset); eval.json `flip_ppd`.
    #[arg(long)]
    pub ppd: Option<f32>,
}

impl EvalCommand {
    pub fn run(self) -> Result<()> {
        run(&EvalArgs {
            reference: &self.reference,
            test: &self.test,
            gaze: &self.gaze,
            rings: self.rings,
            out: &self.out,
            headset: self.headset.as_deref(),
            ppd: self.ppd,
        })
    }
}
