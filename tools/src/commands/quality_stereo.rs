//! `fovea quality --eyes both`: the binocular consistency of a stereo run. Each evaluated frame's
//! right eye is warped into the left through the converged depth (`crate::eval::binocular`: surfaces
//! both eyes see; occlusions and off-screen points masked) and the eyes' displayed difference is
//! averaged per eccentricity ring around the left eye's gaze, beside the same measure on the
//! converged reference pair. The flicker of the difference (its change from frame to frame beyond
//! the reference pair's) joins each eye's own flicker. Each evaluated frame's difference is also
//! written as a heat map, `binocular_NNNN.png` in the run's folder (`binocular::heat_map`).

use crate::eval::binocular::{
    difference_flicker_map, difference_map, heat_map, signed_difference_map, EyeGeometry, Warp,
};
use crate::eval::metrics::{mean, Rings};
use crate::output::{tonemap_preview, write_png};
use anyhow::{Context, Result};
use fovea_hal::Eye;
use fovea_renderer::frame::CameraPose;
use fovea_renderer::passes::tonemap::ToneCurve;
use fovea_renderer::scene::bvh::instanced::SceneBvh;
use fovea_renderer::scene::bvh::BvhBuilder;
use fovea_renderer::scene::Scene;
use fovea_stage::projection::EyeRig;
use glam::Vec2;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

/// Which of a run's files and report.json keys hold one eye.
pub(super) struct EyeFiles {
    /// After `frame_NNNN` in the frame files.
    pub suffix: &'static str,
    /// The report.json key of the eye's gaze per frame.
    pub gaze_key: &'static str,
    /// Whether the latency model's true gaze (`gaze_true`, the left eye's) applies.
    pub latency: bool,
}

impl EyeFiles {
    pub const MONO: EyeFiles = EyeFiles {
        suffix: "",
        gaze_key: "gaze",
        latency: true,
    };
    pub const LEFT: EyeFiles = EyeFiles {
        suffix: "_left",
        gaze_key: "gaze",
        latency: true,
    };
    pub const RIGHT: EyeFiles = EyeFiles {
        suffix: "_right",
        gaze_key: "gaze_right",
        latency: false,
    };
}

/// The right eye's converged references and, per evaluated frame, the warp of the right eye into
/// the left (one for a still camera).
pub(super) struct StereoReferences {
    pub right: Vec<Vec<[f32; 4]>>,
    /// The display exposure both eyes' frames and references are judged at.
    pub exposure: f32,
    warps: Vec<Warp>,
    width: u32,
    height: u32,
}

impl StereoReferences {
    /// `heads`: the head pose of each rendered reference (one for a still camera).
    pub fn new(
        scene: &Scene,
        rig: &EyeRig,
        heads: &[CameraPose],
        right: Vec<Vec<[f32; 4]>>,
        exposure: f32,
    ) -> StereoReferences {
        // The binned builder: the measure needs correct hits, not the GPU's traversal speed.
        let bvh = SceneBvh::build(scene, BvhBuilder::BINNED);
        let warps = heads
            .iter()
            .map(|head| {
                let eye = |e| EyeGeometry::trace(&bvh, rig.eye(head, e), rig.width, rig.height);
                Warp::new(&eye(Eye::Left), &eye(Eye::Right))
            })
            .collect();
        StereoReferences {
            right,
            exposure,
            warps,
            width: rig.width,
            height: rig.height,
        }
    }

    fn warp(&self, frame: usize) -> &Warp {
        &self.warps[frame.min(self.warps.len() - 1)]
    }
}

/// One ring of the binocular measure, means over the evaluated frames.
#[derive(Serialize, Deserialize)]
pub(super) struct BinocularRing {
    ecc_inner: f64,
    ecc_outer: f64,
    /// Share of the ring's pixels whose surface both eyes see (the measure's pixels).
    visible_in_both: f64,
    /// Mean |left − warped right| of the displayed sRGB values (0…1).
    difference: Option<f64>,
    /// The same of the converged reference pair.
    reference_difference: Option<f64>,
    /// difference / reference_difference.
    ratio: Option<f64>,
    /// Frame-to-frame change of the eyes' signed difference beyond the reference pair's.
    difference_flicker: Option<f64>,
}

/// The whole frame's binocular measure, means over the evaluated frames.
#[derive(Serialize, Deserialize)]
pub(super) struct BinocularFrame {
    visible_in_both: f64,
    difference: Option<f64>,
    reference_difference: Option<f64>,
    ratio: Option<f64>,
    difference_flicker: Option<f64>,
}

/// quality.json's `binocular` of a stereo run (`quality` adds the right eye's own quality).
#[derive(Serialize, Deserialize)]
pub(super) struct BinocularQuality {
    /// The right eye warped into the left; rings around the left eye's gaze.
    rings: Vec<BinocularRing>,
    frame: BinocularFrame,
}

/// Per-ring means of one frame's maps (and the whole frame's, last).
struct FrameMeans {
    difference: Vec<Option<f64>>,
    reference: Vec<Option<f64>>,
    visible: Vec<Option<f64>>,
    flicker: Option<Vec<Option<f64>>>,
}

fn ring_means(rings: &Rings, map: &[f64]) -> Vec<Option<f64>> {
    let mut v = rings.mean(map);
    v.push(mean(map));
    v
}

/// A displayed frame of the run (bounded read, its size checked from the header).
fn read_png(path: &Path, width: u32, height: u32) -> Result<Vec<u8>> {
    let max_pixels = fovea_stage::decode::MAX_IMAGE_PIXELS;
    Ok(fovea_stage::decode::read_rgba8(path, max_pixels, Some((width, height)))?.2)
}

/// The binocular measure of the run in `dir` over the evaluated frames, in `rings` rings.
pub(super) fn measure(
    dir: &Path,
    evaluated: &[u32],
    left_references: &[Vec<[f32; 4]>],
    stereo: &StereoReferences,
    rings: usize,
) -> Result<BinocularQuality> {
    let (width, height) = (stereo.width, stereo.height);
    let report_path = dir.join("report.json");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report_path)?)
            .with_context(|| format!("reading {}", report_path.display()))?;
    let mut frames: Vec<FrameMeans> = Vec::new();
    let mut previous: Option<(u32, Vec<f64>, Vec<f64>)> = None;
    let mut edges = Vec::new();
    for (i, &f) in evaluated.iter().enumerate() {
        let g = &report["gaze"][f as usize];
        let gaze = Vec2::new(
            g[0].as_f64().unwrap_or(0.0) as f32,
            g[1].as_f64().unwrap_or(0.0) as f32,
        );
        let ring_set = Rings::new(width, height, gaze, rings);
        if edges.is_empty() {
            let ecc = |r: f64| r / ring_set.r_max * crate::eval::metrics::ECC_MAX;
            edges = (0..rings)
                .map(|r| ring_set.bounds(r))
                .map(|(inner, outer)| (ecc(inner), ecc(outer)))
                .collect();
        }
        let left = read_png(&dir.join(format!("frame_{f:04}_left.png")), width, height)?;
        let right = read_png(&dir.join(format!("frame_{f:04}_right.png")), width, height)?;
        let reference_left = tonemap_preview(&left_references[i], stereo.exposure, ToneCurve::Aces);
        let reference_right = tonemap_preview(&stereo.right[i], stereo.exposure, ToneCurve::Aces);
        let warp = stereo.warp(i);
        write_png(
            &dir.join(format!("binocular_{f:04}.png")),
            width,
            height,
            &heat_map(&left, &right, warp),
        )?;
        let signed = signed_difference_map(&left, &right, warp);
        let reference_signed = signed_difference_map(&reference_left, &reference_right, warp);
        let flicker =
            previous
                .as_ref()
                .filter(|p| p.0 + 1 == f)
                .map(|(_, test_prev, reference_prev)| {
                    let map = difference_flicker_map(
                        test_prev,
                        &signed,
                        reference_prev,
                        &reference_signed,
                    );
                    ring_means(&ring_set, &map)
                });
        frames.push(FrameMeans {
            difference: ring_means(&ring_set, &difference_map(&left, &right, warp)),
            reference: ring_means(
                &ring_set,
                &difference_map(&reference_left, &reference_right, warp),
            ),
            visible: ring_means(&ring_set, &warp.coverage_map()),
            flicker,
        });
        previous = Some((f, signed, reference_signed));
    }
    // Mean over the frames that have a value; slot `rings` is the whole frame.
    let over_frames = |pick: &dyn Fn(&FrameMeans) -> Option<f64>| {
        let values: Vec<f64> = frames.iter().filter_map(pick).collect();
        (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
    };
    let slot = |k: usize| {
        let difference = over_frames(&|m| m.difference[k]);
        let reference_difference = over_frames(&|m| m.reference[k]);
        let ratio = difference
            .zip(reference_difference)
            .filter(|(_, r)| *r > 0.0)
            .map(|(d, r)| d / r);
        let flicker = over_frames(&|m| m.flicker.as_ref().and_then(|f| f[k]));
        let visible = over_frames(&|m| m.visible[k]).unwrap_or(0.0);
        (visible, difference, reference_difference, ratio, flicker)
    };
    let ring_means = (0..rings)
        .map(|k| {
            let (visible_in_both, difference, reference_difference, ratio, difference_flicker) =
                slot(k);
            BinocularRing {
                ecc_inner: edges[k].0,
                ecc_outer: edges[k].1,
                visible_in_both,
                difference,
                reference_difference,
                ratio,
                difference_flicker,
            }
        })
        .collect();
    let (visible_in_both, difference, reference_difference, ratio, difference_flicker) =
        slot(rings);
    Ok(BinocularQuality {
        rings: ring_means,
        frame: BinocularFrame {
            visible_in_both,
            difference,
            reference_difference,
            ratio,
            difference_flicker,
        },
    })
}

/// One row of the stereo tables: the run's label, its measure, and each eye's FLIP and flicker.
pub(super) struct StereoRow<'a> {
    pub label: String,
    pub binocular: &'a BinocularQuality,
    pub flip: [f64; 2],
    pub flicker: [Option<f64>; 2],
}

/// quality.md's stereo tables of one camera.
pub(super) fn markdown(rows: &[StereoRow]) -> String {
    let mut s = String::new();
    let Some(first) = rows.first() else {
        return s;
    };
    let cell = |v: Option<f64>| v.map_or("–".to_string(), |f| format!("{f:.4}"));
    let _ = write!(
        s,
        "Binocular difference: the right eye warped into the left through the converged depth, \
         mean |Δ| of the displayed sRGB over surfaces both eyes see; per ring the run's / the \
         converged pair's (rings around the left eye's gaze)\n\n| method + denoiser, TAA, noise |"
    );
    for ring in &first.binocular.rings {
        let _ = write!(s, " {:.0}–{:.0}° |", ring.ecc_inner, ring.ecc_outer);
    }
    let _ = writeln!(
        s,
        " frame: run / pair | seen by both |\n|---|{}---|---|",
        "---|".repeat(first.binocular.rings.len())
    );
    for row in rows {
        let b = row.binocular;
        let _ = write!(s, "| {} |", row.label);
        for ring in &b.rings {
            let _ = write!(
                s,
                " {} |",
                ring.ratio.map_or("–".to_string(), |r| format!("{r:.2}×"))
            );
        }
        let _ = writeln!(
            s,
            " {} / {} | {:.0} % |",
            cell(b.frame.difference),
            cell(b.frame.reference_difference),
            100.0 * b.frame.visible_in_both
        );
    }
    let _ = writeln!(
        s,
        "\nEach eye against its own reference, and the flicker of each eye and of their \
         difference\n\n| method + denoiser, TAA, noise | FLIP left | FLIP right | flicker left | \
         flicker right | flicker of the difference |\n|---|---|---|---|---|---|"
    );
    for row in rows {
        let _ = writeln!(
            s,
            "| {} | {:.4} | {:.4} | {} | {} | {} |",
            row.label,
            row.flip[0],
            row.flip[1],
            cell(row.flicker[0]),
            cell(row.flicker[1]),
            cell(row.binocular.frame.difference_flicker)
        );
    }
    s.push('\n');
    s
}
