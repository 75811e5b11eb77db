//! `fovea sweep`: a `fovea quality`, `fovea reference` or `fovea replay` run split into
//! independent jobs that a batch scheduler (Slurm job arrays, `scripts/sweep-slurm`) or a shell
//! loop runs, and merged into the files the one-process command writes.
//!
//! A sweep folder holds:
//! - `sweep.json`: the command split, the axes, the commit of the fovea that planned it, the
//!   working folder its relative paths resolve from, the device requirement, the studies (one
//!   one-process command each) and the job count;
//! - `jobs.jsonl`: one job per line (index, stage, the `fovea` arguments whose piece it computes,
//!   which piece, its folder, the jobs it needs). It is derived from `sweep.json`, and every
//!   command checks it line by line against the plan;
//! - `jobs/NNNN/`: what each job writes (`result/` appears whole, by a rename, or not at all;
//!   `failed.json` says why the last attempt failed);
//! - `merged/<study>/`: the one-process command's files, written by `fovea sweep merge`.

mod files;
mod job;
mod merge;
mod open;
mod plan;
mod status;

pub use files::{commit, Axes, Parse, Study};
pub use job::run;
pub use merge::merge;
pub use plan::{plan, PlanArgs};
pub use status::{list, status, ListArgs};

#[cfg(test)]
#[path = "tests.rs"]
mod tests;
