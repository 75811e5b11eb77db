//! The `fovea` command line: the commands and their flags as clap parses them (docs/cli.md is
//! generated from these definitions: the contract). Each command owns its flags and its `run`
//! (`commands::*::*Command`); this module lists them and runs the one given.

use crate::commands;
use crate::commands::render::RenderCommand;
use crate::commands::render_args::RenderOpts;
use anyhow::{bail, Result};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "fovea",
    version,
    about = "Foveated real-time path tracing in Visual-Polar space (Vulkan compute)"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// `fovea` with no arguments renders with every default.
#[derive(Parser)]
struct DefaultRender {
    #[command(flatten)]
    opts: RenderOpts,
}

// Parsed once per run: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
pub enum Command {
    /// Render frames to PNG (and EXR) with a timing report.
    Render(commands::render::RenderCommand),
    /// Real-time rendering in a window: one eye or both side by side, gaze from the mouse (or
    /// --gaze), keys m / n / t cycle method, denoiser and TAA, f freezes the gaze, q or Esc quits.
    View(commands::view::ViewCommand),
    /// Both eyes on a headset through an OpenXR runtime (Vulkan): views and gaze at each frame's
    /// predicted display time; writes DIR/frames.jsonl (one row per frame) and DIR/report.json.
    Xr(commands::xr::XrCommand),
    /// Regression replay: render gaze traces and compare every frame with a stored baseline
    /// (change: FLIP/RMSE per ring; quality against the converged reference; the gaze used;
    /// cost, reported). Exit 0 within tolerance, 1 on a regression, 2 on bad input.
    Replay(commands::replay::ReplayCommand),
    /// Render a converged linear-radiance reference EXR.
    Reference(commands::reference::ReferenceCommand),
    /// Benchmark: BVH build, rays per second, per-pass GPU milliseconds, the real-time loop (one
    /// run, one device).
    Bench(commands::bench::BenchCommand),
    /// List Vulkan devices, the chosen one and its limits.
    Info(commands::info::InfoCommand),
    /// List the headset profiles built in (config/headsets/*.toml).
    Headsets,
    /// Write one of the project's procedural scenes as glTF.
    GenScene(commands::gen_scene::GenSceneCommand),
    /// Quality over a gaze sequence for each method × denoiser × TAA, still and moving camera:
    /// per-ring RMSE/SSIM against converged references → DIR/quality.json + quality.md.
    Quality(commands::quality::QualityCommand),
    /// Gaze error at display time without rendering: recordings through the latency model and
    /// each predictor, every frame against where the eye is when it is shown (median, p95, p99,
    /// share above 2.5° and 5°, per-saccade landing error) → DIR/gaze_eval.json + a table.
    GazeEval(commands::gaze_eval::GazeEvalCommand),
    /// Write the method table into a Markdown file (between its method-table markers) from a
    /// `fovea quality` folder and a `fovea bench` report, with a picture row and the papers' claims.
    MethodTable(commands::method_table::MethodTableCommand),
    /// Perceived quality against cost: `fovea quality` folders scored by FovVideoVDP
    /// (scripts/perceptual) → per scene, size, gaze and camera a table and plots of JOD against
    /// samples and GPU time per frame, one line per method + filters → DIR/perceptual.md + jod_*.png
    PerceptualReport(commands::perceptual_report::PerceptualReportCommand),
    /// Compare a frame with a reference (RMSE, PSNR, SSIM), whole-frame and per eccentricity ring.
    Eval(commands::eval::EvalCommand),
    /// Split `fovea quality`, `fovea reference` or `fovea replay` into independent jobs for a batch
    /// scheduler
    /// (Slurm job arrays: scripts/sweep-slurm) or a shell loop, and merge their results into
    /// the files the one-process command writes (docs/guide/sweeps.md).
    #[command(subcommand)]
    Sweep(SweepCommand),
}

#[derive(Subcommand)]
pub enum SweepCommand {
    /// Write DIR/sweep.json and DIR/jobs.jsonl: the jobs of a `fovea quality …`,
    /// `fovea reference …` or `fovea replay …` command, given after the sweep's own flags
    /// (references split into sample batches whose merge is exact, then one job per combination
    /// or trace).
    Plan {
        /// The sweep folder (new or empty).
        #[arg(long)]
        out: PathBuf,
        /// Scenes, one study (one merged output) each; default the command's --scene (quality and
        /// reference sweeps).
        #[arg(long, value_delimiter = ',')]
        scenes: Vec<String>,
        /// Headset profiles, one study each; default the command's --headset (quality and
        /// reference sweeps).
        #[arg(long, value_delimiter = ',')]
        headsets: Vec<String>,
        /// Gaze sources of a quality sweep, one study each; default the command's --gaze.
        #[arg(long, value_delimiter = ',')]
        gazes: Vec<String>,
        /// Reference batches (16 samples each) per reference job: a power of two.
        #[arg(long, default_value_t = 4)]
        batches_per_job: u32,
        /// The one-process command: `quality …`, `reference …` or `replay …` (comparing with
        /// existing baselines) with that command's flags (without --out).
        #[arg(
            required = true,
            trailing_var_arg = true,
            allow_hyphen_values = true,
            value_name = "COMMAND"
        )]
        command: Vec<String>,
    },
    /// Run job K of the sweep in DIR (K from --index, else the Slurm array task's
    /// SLURM_ARRAY_TASK_ID; plus --offset): its result appears whole in its folder or not at all;
    /// a finished job is left as it is; a failure is recorded and exits non-zero.
    Run {
        /// The sweep folder (`fovea sweep plan --out`).
        dir: PathBuf,
        /// The job: its line in jobs.jsonl, counted from 0.
        #[arg(long)]
        index: Option<u32>,
        /// Added to the index (Slurm arrays whose task ids start at 0).
        #[arg(long, default_value_t = 0)]
        offset: u32,
    },
    /// Every job's state: done, running, failed or missing, with the reason.
    Status {
        /// The sweep folder.
        dir: PathBuf,
        /// As JSON.
        #[arg(long)]
        json: bool,
    },
    /// Job indices, one per line, for a shell loop, GNU parallel or Slurm.
    List {
        /// The sweep folder.
        dir: PathBuf,
        /// Only the jobs of this stage (reference, run).
        #[arg(long)]
        stage: Option<String>,
        /// Only jobs not done.
        #[arg(long)]
        pending: bool,
        /// Print the stages in the order they run instead.
        #[arg(long)]
        stages: bool,
        /// Print Slurm array chunks "OFFSET SPEC" whose task ids stay below this (MaxArraySize).
        #[arg(long)]
        arrays: Option<u32>,
    },
    /// Gather every job's result into DIR/merged/<study>/: the files the one-process command
    /// writes (refused while a job is not done or the jobs ran on different devices).
    Merge {
        /// The sweep folder.
        dir: PathBuf,
    },
}

/// Parses the process's arguments and runs the command (`fovea` alone: `fovea render` with every
/// default).
pub fn run() -> Result<()> {
    let cli = Cli::parse();
    let command = cli.command.unwrap_or_else(|| {
        Command::Render(RenderCommand {
            opts: Box::new(DefaultRender::parse_from(["fovea"]).opts),
            no_overview: false,
            device: commands::flags::DeviceArgs {
                device: None,
                validation: false,
                traversal: "auto".into(),
            },
        })
    });
    if matches!(
        command,
        Command::Render(_) | Command::Xr(_) | Command::Sweep(SweepCommand::Run { .. })
    ) {
        // Only `render`, `xr` and a sweep's job check for it (a clean end); other commands stop
        // at once.
        crate::interrupt::install()?;
    }
    match command {
        Command::Render(c) => c.run(),
        Command::View(c) => c.run(),
        Command::Xr(c) => c.run(),
        Command::Replay(c) => c.run(),
        Command::Reference(c) => c.run(),
        Command::Bench(c) => c.run(),
        Command::Info(c) => c.run(),
        Command::Headsets => commands::headsets::run(),
        Command::GenScene(c) => c.run(),
        Command::Quality(c) => c.run(),
        Command::GazeEval(c) => c.run(),
        Command::MethodTable(c) => c.run(),
        Command::PerceptualReport(c) => c.run(),
        Command::Eval(c) => c.run(),
        Command::Sweep(c) => c.run(),
    }
}

/// A sweep's command (`fovea ARGS…`) parsed as the command line parses it.
fn parse_study(
    argv: &[String],
    f: &mut dyn FnMut(crate::sweep::Study<'_>) -> Result<()>,
) -> Result<()> {
    use crate::sweep::Study;
    let words = std::iter::once("fovea").chain(argv.iter().map(String::as_str));
    let cli = Cli::try_parse_from(words).map_err(|e| {
        let message = e.to_string();
        let first = message
            .lines()
            .next()
            .unwrap_or("")
            .trim_start_matches("error: ");
        anyhow::anyhow!("`fovea {}`: {first}", argv.join(" "))
    })?;
    match cli.command {
        Some(Command::Quality(c)) => c.with_args(&mut |q| f(Study::Quality(q))),
        Some(Command::Reference(c)) => c.with_args(&mut |r| f(Study::Reference(r))),
        Some(Command::Replay(c)) => c.with_args(&mut |r| f(Study::Replay(r))),
        _ => bail!(
            "fovea sweep splits `fovea quality …`, `fovea reference …` or `fovea replay …`, not \
             `fovea {}`",
            argv.join(" ")
        ),
    }
}

impl SweepCommand {
    pub fn run(self) -> Result<()> {
        use crate::sweep;
        match self {
            SweepCommand::Plan {
                out,
                scenes,
                headsets,
                gazes,
                batches_per_job,
                command,
            } => sweep::plan(
                &sweep::PlanArgs {
                    out: &out,
                    command: &command,
                    axes: sweep::Axes {
                        scenes,
                        headsets,
                        gazes,
                    },
                    batches_per_job,
                },
                &parse_study,
            ),
            SweepCommand::Run { dir, index, offset } => {
                sweep::run(&dir, index, offset, &parse_study)
            }
            SweepCommand::Status { dir, json } => sweep::status(&dir, json, &parse_study),
            SweepCommand::List {
                dir,
                stage,
                pending,
                stages,
                arrays,
            } => sweep::list(
                &dir,
                &sweep::ListArgs {
                    stage: stage.as_deref(),
                    pending,
                    stages,
                    arrays,
                },
                &parse_study,
            ),
            SweepCommand::Merge { dir } => sweep::merge(&dir, &parse_study),
        }
    }
}
