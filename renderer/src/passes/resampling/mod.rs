//! Resampling of light samples between the tracer's samples (`--resampling`; Bitterli et al.
//! 2020, ReSTIR DI; docs/design/resampling.md). With `di` the tracer's `*_resampled` variant leaves
//! the primary hit's next-event estimation out and writes the primary hit's barycentrics; two
//! passes in the sampling grid then draw light candidates per sample, reuse the previous frame's
//! reservoir and the neighbours' (`temporal`, `spatial`) and add the chosen sample's direct light
//! to the G-buffer's colour and radiance before any denoiser runs. Per view: the reservoirs are
//! history, like a denoiser's.

mod reservoirs;
mod settings;
mod spatial;
mod temporal;

pub use reservoirs::Reservoirs;
pub use settings::{
    ResamplingMode, ResamplingSettings, MAX_CANDIDATES, MAX_NEIGHBOURS, MAX_TEMPORAL_CAP,
    RADIUS_RANGE,
};

use crate::error::{Error, Result};
use crate::gpu_scene::GpuScene;
use crate::graph::FrameRecorder;
use crate::layouts::ReservoirGpu;
use crate::passes::grid::GridFrame;
use crate::passes::Pass;
use crate::sampling::SamplingSpace;
use crate::vk::{Buffer, Context};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// A view's resampling: its two passes, its reservoirs and how many frames they hold.
pub struct Resampling {
    pub settings: ResamplingSettings,
    temporal: Pass<temporal::Temporal>,
    spatial: Pass<spatial::Spatial>,
    reservoirs: Reservoirs,
    frames: u64,
}

impl Resampling {
    /// The passes for `space`'s grid; an error naming the space where its grid runs no temporal
    /// filters (the passes address the grid as the denoisers do).
    pub fn new(
        ctx: &Arc<Context>,
        space: &dyn SamplingSpace,
        settings: ResamplingSettings,
    ) -> Result<Resampling> {
        settings.validate()?;
        let caps = space.capabilities();
        if !caps.temporal_filters {
            return Err(Error::Invalid(format!(
                "resampling '{}': the {} space cannot reuse samples between its texels {}",
                settings.mode.name(),
                space.name(),
                caps.filters_note
            )));
        }
        let grid = space.grid_size();
        let bytes = grid.x as u64 * grid.y as u64 * std::mem::size_of::<ReservoirGpu>() as u64;
        let buffer = |name: &str| {
            Buffer::new(
                ctx,
                name,
                bytes,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::GpuOnly,
            )
        };
        let variant = space.shader_variant();
        Ok(Resampling {
            settings,
            temporal: Pass::new(ctx, variant)?,
            spatial: Pass::new(ctx, variant)?,
            reservoirs: Reservoirs {
                history: buffer("resampling.history")?,
                fresh: buffer("resampling.fresh")?,
            },
            frames: 0,
        })
    }

    /// GPU bytes carried between frames (and the first pass's output).
    pub fn history_bytes(&self) -> u64 {
        self.reservoirs.history.size + self.reservoirs.fresh.size
    }

    /// Passes one frame records.
    pub const PASSES: u32 = 2;

    /// Records both passes after the trace (`*_resampled` variant) wrote `frame.gbuffer`; the
    /// first frame, and any frame without `frame.previous`, starts without history.
    pub fn record(
        &mut self,
        rec: &mut FrameRecorder,
        frame: &GridFrame,
        scene: &GpuScene,
        ray_counters: &Buffer,
    ) -> Result<()> {
        let primary_hit = frame.gbuffer.primary_hit.as_ref().ok_or_else(|| {
            Error::Invalid("resampling needs the G-buffer's primary-hit image".into())
        })?;
        let shared = (scene, ray_counters, primary_hit);
        let fresh_start = self.frames == 0;
        self.temporal.record(
            rec,
            frame,
            shared,
            (&self.reservoirs, fresh_start),
            &self.settings,
        )?;
        self.spatial
            .record(rec, frame, shared, &self.reservoirs, &self.settings)?;
        self.frames += 1;
        Ok(())
    }
}
