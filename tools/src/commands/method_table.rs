//! `fovea method-table`: one table of every foveation method, generated from a
//! `fovea quality` run (quality per ring band, samples, rays) and a `fovea bench` report (cost:
//! whole frames of every method interleaved in one run on one device), written into a Markdown
//! document (docs/quality.md by default) between `<!-- method-table:begin -->` and `<!-- method-table:end -->`, with a picture row
//! (each method's last evaluated still frame and its FLIP map against the reference) and the
//! papers' claims each figure confirms or refutes.

use crate::eval::flip::{flip_image, flip_map};
use crate::output::{read_exr, tonemap_preview, write_png, write_text};
use anyhow::{bail, Context, Result};
use fovea_renderer::passes::tonemap::ToneCurve;
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub const BEGIN: &str = "<!-- method-table:begin -->";
pub const END: &str = "<!-- method-table:end -->";

/// Ring bands of the paper's normalised eccentricity (degrees): a ring belongs to the band its
/// middle falls in.
const BANDS: [(&str, f64, f64); 3] = [
    ("fovea", 0.0, 10.0),
    ("mid", 10.0, 30.0),
    ("periphery", 30.0, f64::INFINITY),
];

#[derive(Deserialize)]
struct Quality {
    scene: String,
    width: u32,
    height: u32,
    gaze_source: String,
    frames: u32,
    eval_frames: u32,
    reference_spp: u32,
    runs: Vec<Run>,
    #[serde(default)]
    refused: Vec<Refused>,
}

#[derive(Deserialize)]
struct Run {
    camera: String,
    method: String,
    denoiser: String,
    taa: String,
    samples_traced: u64,
    rays_traced: u64,
    frames: Vec<u32>,
    rings: Vec<Ring>,
}

#[derive(Deserialize)]
struct Ring {
    ecc_inner: f64,
    ecc_outer: f64,
    flip: Option<f64>,
    flicker: Option<f64>,
}

#[derive(Deserialize)]
struct Refused {
    camera: String,
    method: String,
    denoiser: String,
    reason: String,
}

#[derive(Deserialize)]
struct Bench {
    device: String,
    visual_polar: Vec<BenchSize>,
}

#[derive(Deserialize)]
struct BenchSize {
    scene: String,
    width: u32,
    height: u32,
    vp_samples: u64,
    /// Reports before off-screen culling have none: every sample was traced.
    vp_samples_traced: Option<u64>,
    cartesian_passes_ms: BTreeMap<String, f64>,
    vp_passes_ms: BTreeMap<String, f64>,
    cartesian_frame_ms: f64,
    vp_frame_ms: f64,
    comparators: Vec<BenchMethod>,
}

#[derive(Deserialize)]
struct BenchMethod {
    method: String,
    samples: u64,
    samples_traced: Option<u64>,
    passes_ms: BTreeMap<String, f64>,
    frame_ms: f64,
}

/// One method's cost in the bench run: samples traced, frame ms, trace ms.
struct Cost {
    samples: u64,
    frame_ms: f64,
    trace_ms: f64,
}

pub struct MethodTableArgs<'a> {
    /// A `fovea quality` output folder (quality.json, run_*/, reference_still_0000.exr).
    pub quality: &'a Path,
    /// `fovea bench` report.json files: the first gives the table's costs, every one a figure per
    /// scene in the claims.
    pub bench: &'a [std::path::PathBuf],
    /// The Markdown document the table goes into, between its markers.
    pub doc: &'a Path,
    /// Where the picture row's images go (linked relative to the document's folder).
    pub pictures: &'a Path,
    /// `fovea quality` reports of `vp` and one other method at VP's sample count: a claim each.
    pub equal_samples: &'a [std::path::PathBuf],
}

fn read<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text)
        .with_context(|| format!("{}: not the expected report", path.display()))
}

pub fn run(args: &MethodTableArgs) -> Result<()> {
    let quality: Quality = read(&args.quality.join("quality.json"))?;
    let mut benches = Vec::new();
    for path in args.bench {
        let bench: Bench = read(path)?;
        if bench.visual_polar.is_empty() {
            bail!(
                "{}: no visual_polar section (run fovea bench with --vp-sizes)",
                path.display()
            );
        }
        benches.push(bench);
    }
    let Some(bench) = benches.first() else {
        bail!("--bench: at least one fovea bench report")
    };
    let size = &bench.visual_polar[0];
    let doc = std::fs::read_to_string(args.doc)
        .with_context(|| format!("reading {}", args.doc.display()))?;
    // The markers on lines of their own (the document may quote them elsewhere).
    let line_of = |marker: &str| {
        doc.match_indices(marker).map(|(i, _)| i).find(|&i| {
            (i == 0 || doc[..i].ends_with('\n')) && doc[i + marker.len()..].starts_with('\n')
        })
    };
    let (Some(begin), Some(end)) = (line_of(BEGIN), line_of(END)) else {
        bail!("{}: needs the markers {BEGIN} and {END}, each on a line of its own, around the table's place", args.doc.display())
    };
    if end < begin {
        bail!("{}: {END} comes before {BEGIN}", args.doc.display());
    }
    let costs = costs(size);
    let pictures = pictures(args, &quality)?;
    let mut table = String::new();
    write_table(&mut table, &quality, bench, size, &costs);
    write_pictures(&mut table, &pictures, args)?;
    let scenes: Vec<(String, BTreeMap<String, Cost>)> = benches
        .iter()
        .flat_map(|b| &b.visual_polar)
        .map(|v| {
            (
                format!("{} {}×{}", scene_name(&v.scene), v.width, v.height),
                self::costs(v),
            )
        })
        .collect();
    write_claims(&mut table, &quality, &costs, &scenes);
    for path in args.equal_samples {
        write_equal_samples_claim(&mut table, path, &read(path)?)?;
    }
    table.push('\n');
    let updated = format!("{}{BEGIN}\n{table}{}", &doc[..begin], &doc[end..]);
    write_text(args.doc, &updated)?;
    println!("{table}");
    Ok(())
}

fn costs(size: &BenchSize) -> BTreeMap<String, Cost> {
    let trace = |p: &BTreeMap<String, f64>| p.get("trace").copied().unwrap_or(0.0);
    let screen = size.width as u64 * size.height as u64;
    let mut out = BTreeMap::from([
        (
            "cartesian".to_string(),
            Cost {
                samples: screen,
                frame_ms: size.cartesian_frame_ms,
                trace_ms: trace(&size.cartesian_passes_ms),
            },
        ),
        (
            "vp".to_string(),
            Cost {
                samples: size.vp_samples_traced.unwrap_or(size.vp_samples),
                frame_ms: size.vp_frame_ms,
                trace_ms: trace(&size.vp_passes_ms),
            },
        ),
    ]);
    for m in &size.comparators {
        out.insert(
            m.method.clone(),
            Cost {
                samples: m.samples_traced.unwrap_or(m.samples),
                frame_ms: m.frame_ms,
                trace_ms: trace(&m.passes_ms),
            },
        );
    }
    out
}

/// A run's mean of `metric` over the rings of each band ("–" where none).
fn bands(run: &Run, metric: impl Fn(&Ring) -> Option<f64>) -> String {
    let cells: Vec<String> = BANDS
        .iter()
        .map(|&(_, lo, hi)| {
            let values: Vec<f64> = run
                .rings
                .iter()
                .filter(|r| (lo..hi).contains(&(0.5 * (r.ecc_inner + r.ecc_outer))))
                .filter_map(&metric)
                .collect();
            if values.is_empty() {
                "–".to_string()
            } else {
                format!("{:.3}", values.iter().sum::<f64>() / values.len() as f64)
            }
        })
        .collect();
    cells.join(" / ")
}

fn write_table(
    s: &mut String,
    q: &Quality,
    bench: &Bench,
    size: &BenchSize,
    costs: &BTreeMap<String, Cost>,
) {
    let _ = writeln!(
        s,
        "Generated by `fovea method-table` from `fovea quality` ({} at {}×{}, gaze `{}`, {} frames, the last {} evaluated against {}-spp references; \
         FLIP and flicker per band of the paper's normalised eccentricity — fovea < 10°, mid 10–30°, periphery > 30°) and `fovea bench` \
         (cost: {} at {}×{}, gaze centred, no denoiser, every method's frames interleaved in one run on {}).\n",
        q.scene, q.width, q.height, q.gaze_source, q.frames, q.eval_frames, q.reference_spp, size.scene, size.width, size.height, bench.device
    );
    let _ = writeln!(
        s,
        "| method + denoiser | samples / rays per frame | bench: samples, frame ms (× Cartesian), trace µs per 1k samples | FLIP still: fovea / mid / periphery | flicker still | flicker moving |\n|---|---|---|---|---|---|"
    );
    let cartesian_ms = costs.get("cartesian").map_or(f64::NAN, |c| c.frame_ms);
    for run in q
        .runs
        .iter()
        .filter(|r| r.camera == "still" && r.taa == "off")
    {
        let moving = q.runs.iter().find(|m| {
            m.camera == "moving"
                && m.method == run.method
                && m.denoiser == run.denoiser
                && m.taa == run.taa
        });
        let cost = match (run.denoiser.as_str(), costs.get(&run.method)) {
            ("none", Some(c)) => format!(
                "{}, {:.1} ({:.2}×), {:.1}",
                c.samples,
                c.frame_ms,
                c.frame_ms / cartesian_ms,
                1e6 * c.trace_ms / c.samples.max(1) as f64
            ),
            _ => "–".to_string(),
        };
        let _ = writeln!(
            s,
            "| {} + {} | {} / {} | {cost} | {} | {} | {} |",
            run.method,
            run.denoiser,
            run.samples_traced,
            run.rays_traced,
            bands(run, |r| r.flip),
            bands(run, |r| r.flicker),
            moving.map_or("–".to_string(), |m| bands(m, |r| r.flicker))
        );
    }
    for r in q.refused.iter().filter(|r| r.camera == "still") {
        let _ = writeln!(
            s,
            "| {} + {} | refused: {} | | | | |",
            r.method, r.denoiser, r.reason
        );
    }
    s.push('\n');
}

/// Each method's last evaluated still frame without a denoiser and its FLIP map, written to
/// `args.pictures`: (method, frame file, map file).
fn pictures(args: &MethodTableArgs, q: &Quality) -> Result<Vec<(String, String, String)>> {
    let reference_path = args.quality.join("reference_still_0000.exr");
    let (w, h, reference) = read_exr(&reference_path)?;
    let reference = tonemap_preview(&reference, 1.0, ToneCurve::Aces);
    std::fs::create_dir_all(args.pictures)
        .with_context(|| format!("creating {}", args.pictures.display()))?;
    write_png(&args.pictures.join("reference.png"), w, h, &reference)?;
    let ppd = crate::eval::flip::headset_ppd(&fovea_hal::HmdDescription::resolve("fove0")?, w);
    let mut out = Vec::new();
    for run in q
        .runs
        .iter()
        .filter(|r| r.camera == "still" && r.denoiser == "none" && r.taa == "off")
    {
        let Some(&last) = run.frames.last() else {
            continue;
        };
        let dir = args
            .quality
            .join(format!("run_still_{}_none_taa-off", run.method));
        let frame_path = dir.join(format!("frame_{last:04}.png"));
        // The frame must have the reference's size (FLIP compares pixel by pixel).
        let (_, _, frame) = fovea_stage::decode::read_rgba8(
            &frame_path,
            fovea_stage::decode::MAX_IMAGE_PIXELS,
            Some((w, h)),
        )?;
        let map = flip_image(&flip_map(&reference, &frame, w, h, ppd), w, h);
        let (frame_name, map_name) = (
            format!("{}.png", run.method),
            format!("{}_flip.png", run.method),
        );
        write_png(&args.pictures.join(&frame_name), w, h, &frame)?;
        write_png(&args.pictures.join(&map_name), w, h, &map)?;
        out.push((run.method.clone(), frame_name, map_name));
    }
    Ok(out)
}

fn write_pictures(
    s: &mut String,
    pictures: &[(String, String, String)],
    args: &MethodTableArgs,
) -> Result<()> {
    let dir = link_dir(args.doc, args.pictures);
    let _ = writeln!(s, "Still camera, no denoiser, the last evaluated frame (same gaze for every method); below each, its FLIP map against the reference (`{dir}/reference.png`).\n");
    let _ = writeln!(
        s,
        "| {} |",
        pictures
            .iter()
            .map(|p| p.0.as_str())
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let _ = writeln!(s, "|{}", "---|".repeat(pictures.len()));
    let _ = writeln!(
        s,
        "| {} |",
        pictures
            .iter()
            .map(|p| format!("![{}]({dir}/{})", p.0, p.1))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let _ = writeln!(
        s,
        "| {} |\n",
        pictures
            .iter()
            .map(|p| format!("![{} FLIP]({dir}/{})", p.0, p.2))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    Ok(())
}

/// `pictures` as a link from `doc`'s folder: a folder under the document's is linked from there;
/// another through `../` steps, compared as the real paths when both exist; a path that cannot be
/// related (one absolute, one relative, `..` left after resolving) as given.
fn link_dir(doc: &Path, pictures: &Path) -> String {
    use std::path::{Component, PathBuf};
    let base = doc.parent().unwrap_or(Path::new(""));
    if let Ok(inner) = pictures.strip_prefix(base) {
        return inner.display().to_string();
    }
    let (base, target): (PathBuf, PathBuf) = match (base.canonicalize(), pictures.canonicalize()) {
        (Ok(b), Ok(p)) => (b, p),
        _ => (base.to_path_buf(), pictures.to_path_buf()),
    };
    fn plain(p: &Path) -> Option<Vec<Component<'_>>> {
        let parts: Vec<Component> = p
            .components()
            .filter(|c| !matches!(c, Component::CurDir))
            .collect();
        (!parts.contains(&Component::ParentDir)).then_some(parts)
    }
    let rooted = |parts: &[Component]| {
        parts
            .first()
            .is_some_and(|c| matches!(c, Component::RootDir | Component::Prefix(_)))
    };
    match (plain(&base), plain(&target)) {
        (Some(base), Some(target)) if rooted(&base) == rooted(&target) => {
            let shared = base.iter().zip(&target).take_while(|(a, b)| a == b).count();
            let mut parts = vec!["..".to_string(); base.len() - shared];
            parts.extend(
                target[shared..]
                    .iter()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned()),
            );
            parts.join("/")
        }
        _ => pictures.display().to_string(),
    }
}

/// A scene path's file stem (reports name scenes by path or by name).
fn scene_name(scene: &str) -> &str {
    Path::new(scene)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or(scene)
}

/// The papers' claims against this run's figures (`scenes`: every bench screen's costs).
fn write_claims(
    s: &mut String,
    q: &Quality,
    costs: &BTreeMap<String, Cost>,
    scenes: &[(String, BTreeMap<String, Cost>)],
) {
    let per_sample = |c: &BTreeMap<String, Cost>, m: &str| {
        c.get(m).map(|c| c.trace_ms / c.samples.max(1) as f64)
    };
    let flip = |m: &str| {
        q.runs
            .iter()
            .find(|r| {
                r.camera == "still" && r.method == m && r.denoiser == "none" && r.taa == "off"
            })
            .map(|r| bands(r, |g| g.flip))
    };
    let _ = writeln!(
        s,
        "Claims (trace time per sample from the bench, per scene; ≥ 1.15× counts as confirmed):\n"
    );
    for (other, paper, claim) in [
        (
            "linear-falloff",
            "Koskela et al. 2019",
            "≈ 1.3× faster traversal per sample for Visual-Polar than linear falloff",
        ),
        (
            "random-acuity",
            "Koskela et al. 2019 / 2018",
            "1.3–1.5× faster traversal per sample for Visual-Polar than random acuity samples",
        ),
    ] {
        let figures: Vec<String> = scenes
            .iter()
            .filter_map(|(name, c)| {
                let ratio = per_sample(c, other)? / per_sample(c, "vp")?;
                Some(format!(
                    "{ratio:.2}× on {name} ({})",
                    if ratio >= 1.15 {
                        "confirmed"
                    } else {
                        "not confirmed"
                    }
                ))
            })
            .collect();
        if !figures.is_empty() {
            let _ = writeln!(s, "- {paper}: {claim} — measured {}.", figures.join(", "));
        }
    }
    let samples = |m: &str| {
        q.runs
            .iter()
            .find(|r| r.camera == "still" && r.method == m)
            .map(|r| r.samples_traced)
    };
    for (other, paper) in [
        ("log-polar", "Meng et al. 2018"),
        ("composite", "Andersson & Hansson 2020"),
    ] {
        if let (Some(vp), Some(o), Some(nv), Some(no)) =
            (flip("vp"), flip(other), samples("vp"), samples(other))
        {
            let _ = writeln!(s, "- Visual-Polar vs {other} ({paper}), no denoiser: FLIP {vp} with {nv} samples vs {o} with {no} (each at its paper's budget, not equal samples).");
        }
    }
    if let (Some(t), Some(v), Some(tf), Some(vf)) = (
        costs.get("vrs-tiles"),
        costs.get("vp"),
        flip("vrs-tiles"),
        flip("vp"),
    ) {
        let _ = writeln!(
            s,
            "- Variable-rate tiles (VP's density quantised to 1×1 / 2×2 / 4×4 blocks in 16×16 tiles, never sparser than VP): {} samples = {:.2}× VP's, frame {:.2}× VP's, FLIP {tf} vs VP's {vf}.",
            t.samples,
            t.samples as f64 / v.samples.max(1) as f64,
            t.frame_ms / v.frame_ms
        );
    }
    if let (Some(pb), Some(c), Some(pf), Some(cf)) = (
        costs.get("pixel-blocks"),
        costs.get("cartesian"),
        flip("pixel-blocks"),
        flip("cartesian"),
    ) {
        let _ = writeln!(
            s,
            "- Pixel blocks (Mohanto et al. 2023: 23–30× faster than uniform 32 spp, offline): its frames take {:.2}× the time of one sample per pixel here, FLIP {pf} vs {cf}.",
            pb.frame_ms / c.frame_ms
        );
    }
}

/// The paper a comparator at equal samples stands for.
fn paper_of(method: &str) -> &'static str {
    match method {
        "log-polar" => "Meng et al. 2018",
        "composite" => "Andersson & Hansson 2020",
        "linear-falloff" => "Weier et al. 2016",
        "random-acuity" => "Koskela et al. 2018",
        "pixel-blocks" => "Mohanto et al. 2023",
        "fixed-foveation" => "the same grid held on the lens centre: fixed foveated rendering, what eye tracking is measured against",
        _ => "a comparator",
    }
}

/// One claim line from a quality report of `vp` and one other method at (about) VP's sample
/// count: FLIP per band for every denoiser both ran, still camera.
fn write_equal_samples_claim(s: &mut String, path: &Path, q: &Quality) -> Result<()> {
    fn still_runs<'q>(q: &'q Quality, method: &'q str) -> impl Iterator<Item = &'q Run> + 'q {
        q.runs
            .iter()
            .filter(move |r| r.camera == "still" && r.method == method && r.taa == "off")
    }
    let still = |m| still_runs(q, m);
    let others: BTreeSet<&str> = q
        .runs
        .iter()
        .map(|r| r.method.as_str())
        .filter(|&m| m != "vp")
        .collect();
    let others: Vec<&str> = others.into_iter().collect();
    let (Some(vp), [other]) = (still("vp").next(), others.as_slice()) else {
        bail!(
            "{}: an equal-samples report needs still runs of vp and exactly one other method",
            path.display()
        )
    };
    let other = *other;
    let Some(theirs) = still(other).next() else {
        bail!("{}: no still run of {other}", path.display())
    };
    let figures: Vec<String> = still("vp")
        .filter_map(|v| {
            still(other).find(|o| o.denoiser == v.denoiser).map(|o| {
                format!(
                    "{} {} vs {}",
                    v.denoiser,
                    bands(v, |g| g.flip),
                    bands(o, |g| g.flip)
                )
            })
        })
        .collect();
    let _ = writeln!(
        s,
        "- Visual-Polar vs {other} ({}) at equal samples ({} vs {}, gaze `{}`, `{}`): FLIP {}.",
        paper_of(other),
        vp.samples_traced,
        theirs.samples_traced,
        q.gaze_source,
        path.display(),
        figures.join("; ")
    );
    Ok(())
}

// `fovea method-table` (its help is the variant's in `crate::cli::Command`).
#[derive(clap::Args)]
pub struct MethodTableCommand {
    /// A `fovea quality` output folder (e.g. run with `--methods all`).
    #[arg(long)]
    pub quality: PathBuf,
    /// `fovea bench` report.json files, comma-separated: the first one's first `--vp-sizes`
    /// screen gives the table's costs; every screen of every one a figure in the claims.
    #[arg(long, value_delimiter = ',', required = true)]
    pub bench: Vec<PathBuf>,
    /// The Markdown document to write the table into, between its method-table markers.
    #[arg(long, alias = "readme", default_value = "docs/quality.md")]
    pub doc: PathBuf,
    /// Folder for the picture row's images.
    #[arg(long, default_value = "docs/methods")]
    pub pictures: PathBuf,
    /// `fovea quality` reports (quality.json), comma-separated, each of `vp` and one other
    /// method at VP's sample count (a profile's budget knob): one claim line each.
    #[arg(long, value_delimiter = ',')]
    pub equal_samples: Vec<PathBuf>,
}

impl MethodTableCommand {
    pub fn run(self) -> Result<()> {
        run(&MethodTableArgs {
            quality: &self.quality,
            bench: &self.bench,
            doc: &self.doc,
            pictures: &self.pictures,
            equal_samples: &self.equal_samples,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::link_dir;
    use std::path::Path;

    #[test]
    fn pictures_are_linked_from_the_documents_folder() {
        let link = |doc: &str, pictures: &str| link_dir(Path::new(doc), Path::new(pictures));
        assert_eq!(link("docs/quality.md", "docs/methods"), "methods");
        assert_eq!(link("README.md", "docs/methods"), "docs/methods");
        assert_eq!(link("./docs/quality.md", "docs/methods"), "methods");
        assert_eq!(link("docs/guide/x.md", "docs/methods"), "../methods");
        assert_eq!(link("a/b.md", "c/d"), "../c/d");
        assert_eq!(link("/abs/q.md", "docs/methods"), "docs/methods");
        // Real folders are related through their real paths, `..` in the way or not.
        let root = std::env::temp_dir().join(format!("fovea-link-dir-{}", std::process::id()));
        std::fs::create_dir_all(root.join("docs/methods")).unwrap();
        std::fs::create_dir_all(root.join("other")).unwrap();
        let doc = root.join("other/../docs/quality.md");
        let pictures = root.join("docs/methods");
        assert_eq!(link_dir(&doc, &pictures), "methods");
        assert_eq!(
            link_dir(&root.join("other/x.md"), &pictures),
            "../docs/methods"
        );
        std::fs::remove_dir_all(&root).unwrap();
    }
}
