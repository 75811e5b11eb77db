//! `fovea bench`'s headset loop (`--loop-scenes`, `--loop-headsets`): both eyes of real scenes at
//! the built-in headset profiles' recommended per-eye sizes, the head on the default orbit and the
//! simulated gaze, one stereo renderer with 2 frames in flight and the default profile's cross-eye
//! reuse, as `fovea render --eyes both` runs.
//! Per scene and size three runs, VP + SVGF, VP + A-SVGF and Cartesian + SVGF, each made twice in
//! the order A B C C B A: frames/s, per-pass GPU ms, and the VP / Cartesian ratio of the whole
//! stereo frame (how the saving changes with resolution).

use super::bench_loop::{
    run, LoopRun, LoopScene, LoopSetup, Sums, MOVING_GAZE, STEREO_2, WARMUP_FRAMES,
};
use anyhow::{bail, Context as _, Result};
use fovea_hal::{Eye, HmdDescription};
use fovea_renderer::vk::Context;
use serde::Serialize;
use std::sync::Arc;

/// The methods compared at each size: (method, denoiser).
const RUNS: [(&str, &str); 3] = [("vp", "svgf"), ("vp", "asvgf"), ("cartesian", "svgf")];
const ORDER: [usize; 6] = [0, 1, 2, 2, 1, 0];
/// The headset whose frusta a bare `WxH` size renders through.
const SIZE_HEADSET: &str = "fove0";
/// `--loop-headsets`' default: the eye-tracked headsets of the built-in profiles beyond the
/// FOVE 0, at their recommended per-eye sizes.
pub const DEFAULT_HEADSETS: &str = "quest_pro,psvr2,varjo_aero,pimax_crystal,varjo_xr4";

/// One entry of `--loop-headsets`: a headset at its recommended per-eye size, or a per-eye size
/// through the FOVE 0's frusta.
#[derive(Clone, Debug)]
pub struct LoopHeadset {
    pub hmd: HmdDescription,
    pub width: u32,
    pub height: u32,
}

impl LoopHeadset {
    /// `ID` (a built-in headset or a profile file) or `WxH`.
    pub fn parse(spec: &str) -> Result<LoopHeadset> {
        if let Some((w, h)) = spec.split_once('x').filter(|(w, h)| {
            !w.is_empty()
                && !h.is_empty()
                && (w.chars().chain(h.chars())).all(|c| c.is_ascii_digit())
        }) {
            let (width, height): (u32, u32) = (w.parse()?, h.parse()?);
            if width == 0 || height == 0 {
                bail!("{spec}: a per-eye size of at least 1×1");
            }
            let hmd = HmdDescription::resolve(SIZE_HEADSET)?;
            return Ok(LoopHeadset { hmd, width, height });
        }
        let hmd = HmdDescription::resolve(spec).with_context(|| format!("headset {spec}"))?;
        let eye = hmd.eye(Eye::Left);
        let (width, height) = (eye.recommended_width, eye.recommended_height);
        Ok(LoopHeadset { hmd, width, height })
    }

    /// Every entry of a comma list.
    pub fn parse_list(list: &str) -> Result<Vec<LoopHeadset>> {
        list.split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(LoopHeadset::parse)
            .collect::<Result<_>>()
            .context("--loop-headsets")
    }
}

#[derive(Serialize)]
pub struct HeadsetLoopReport {
    pub scene: String,
    pub headset: String,
    /// The BVH traversal the frames ran (the context's: the first of `--traversal`).
    pub traversal: &'static str,
    /// Per eye.
    pub width: u32,
    pub height: u32,
    pub eyes: u32,
    /// The head's motion: the default orbit of `fovea render --camera-path` (a ±8° yaw swing,
    /// one swing over each run's frames, warm-up included).
    pub camera: &'static str,
    /// The gaze: `--gaze` as `fovea render` takes it.
    pub gaze: &'static str,
    pub warmup_frames: u32,
    /// Timed frames each time a run is made (after its own warm-up frames).
    pub frames: u32,
    /// Times each run is made (order A B C C B A); every figure is over all of them.
    pub repeats: u32,
    /// VP + SVGF, VP + A-SVGF, Cartesian + SVGF.
    pub runs: Vec<MethodRun>,
    /// VP + SVGF / Cartesian + SVGF: wall ms per frame and GPU ms per frame (< 1: VP is cheaper).
    pub vp_vs_cartesian_frame_time: f64,
    pub vp_vs_cartesian_gpu_ms: f64,
}

#[derive(Serialize)]
pub struct MethodRun {
    pub method: String,
    pub denoiser: String,
    #[serde(flatten)]
    pub run: LoopRun,
}

/// Every scene at every headset size.
pub fn measure(
    ctx: &Arc<Context>,
    scenes: &[String],
    headsets: &[LoopHeadset],
    frames: u32,
) -> Result<Vec<HeadsetLoopReport>> {
    super::bench_loop::check_frames(frames)?;
    let mut reports = Vec::new();
    for name in scenes {
        let scene = LoopScene::load(name)?;
        for headset in headsets {
            let size = (headset.width, headset.height);
            let setups = RUNS
                .iter()
                .map(|&run| {
                    LoopSetup::new(
                        &scene,
                        headset.hmd.clone(),
                        size,
                        run,
                        Some(WARMUP_FRAMES + frames),
                    )
                })
                .collect::<Result<Vec<_>>>()?;
            let mut sums: [Sums; 3] = Default::default();
            for i in ORDER {
                sums[i].add(run(ctx, &setups[i], &STEREO_2, frames)?);
            }
            let runs: Vec<MethodRun> = sums
                .into_iter()
                .zip(RUNS)
                .map(|(s, (method, denoiser))| MethodRun {
                    method: method.to_string(),
                    denoiser: denoiser.to_string(),
                    run: s.report(),
                })
                .collect();
            let (vp, cartesian) = (&runs[0].run, &runs[2].run);
            let report = HeadsetLoopReport {
                scene: name.clone(),
                headset: headset.hmd.id.clone(),
                traversal: ctx.traversal.name(),
                width: headset.width,
                height: headset.height,
                eyes: 2,
                camera: "orbit",
                gaze: MOVING_GAZE,
                warmup_frames: WARMUP_FRAMES,
                frames,
                repeats: (ORDER.len() / RUNS.len()) as u32,
                vp_vs_cartesian_frame_time: vp.wall_ms_per_frame / cartesian.wall_ms_per_frame,
                vp_vs_cartesian_gpu_ms: vp.gpu_ms_per_frame / cartesian.gpu_ms_per_frame,
                runs,
            };
            print(&report, &ctx.info.name);
            reports.push(report);
        }
    }
    Ok(reports)
}

/// One Markdown table per scene and size (ready for docs/performance.md).
fn print(r: &HeadsetLoopReport, device: &str) {
    println!(
        "headset loop {} {} 2 × {}×{} (orbit, gaze {}, {} traversal; {} × {} timed frames after {} warm-up, order A B C C B A) on {device}:",
        r.scene, r.headset, r.width, r.height, r.gaze, r.traversal, r.repeats, r.frames, r.warmup_frames
    );
    println!("| method | frames/s | wall ms/frame | GPU ms/frame | trace ms | largest other passes (ms) |");
    println!("|---|---|---|---|---|---|");
    for m in &r.runs {
        let run = &m.run;
        let trace: f64 = run
            .passes_ms
            .iter()
            .filter(|(k, _)| k.starts_with("trace"))
            .map(|(_, v)| v)
            .sum();
        let mut others: Vec<(&String, &f64)> = run
            .passes_ms
            .iter()
            .filter(|(k, _)| !k.starts_with("trace"))
            .collect();
        others.sort_by(|a, b| b.1.total_cmp(a.1));
        let others: Vec<String> = others
            .iter()
            .take(3)
            .map(|(k, v)| format!("{k} {v:.2}"))
            .collect();
        println!(
            "| {} + {} | {:.1} | {:.2} | {:.2} | {:.2} | {} |",
            m.method,
            m.denoiser,
            run.frames_per_second,
            run.wall_ms_per_frame,
            run.gpu_ms_per_frame,
            trace,
            others.join(", ")
        );
    }
    println!(
        "VP / Cartesian (SVGF, whole stereo frame): wall {:.3}, GPU {:.3}",
        r.vp_vs_cartesian_frame_time, r.vp_vs_cartesian_gpu_ms
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headsets_and_sizes_parse() {
        let h = LoopHeadset::parse("psvr2").unwrap();
        assert_eq!(
            (h.hmd.id.as_str(), h.width, h.height),
            ("psvr2", 2400, 2448)
        );
        let s = LoopHeadset::parse("640x720").unwrap();
        assert_eq!(
            (s.hmd.id.as_str(), s.width, s.height),
            (SIZE_HEADSET, 640, 720)
        );
        assert!(LoopHeadset::parse("0x720").is_err());
        let err = format!("{:#}", LoopHeadset::parse_list("psvr2,nope").unwrap_err());
        assert!(
            err.contains("--loop-headsets") && err.contains("nope"),
            "{err}"
        );
        assert_eq!(LoopHeadset::parse_list(DEFAULT_HEADSETS).unwrap().len(), 5);
    }
}
