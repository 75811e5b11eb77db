//! Resampling of light samples between the tracer's samples (`--resampling`; Bitterli et al.
//! 2020, ReSTIR DI; docs/design/resampling.md). With `di` the tracer's `*_resampled` variant leaves
//! the primary hit's next-event estimation out and writes the primary hit's barycentrics; two
//! passes in the sampling grid then draw light candidates per sample, reuse the previous frame's
//! reservoir and the neighbours' (`temporal`, `spatial`) and add the chosen sample's direct light
//! to the G-buffer's colour and radiance before any denoiser runs. With `di+gi` the tracer's
//! `*_resampled_gi` variant also leaves the primary hit's bounce out and writes its secondary hit
//! and the radiance gathered there; two more passes (ReSTIR GI, Ouyang et al. 2021; the GI
//! kernels of `temporal` and `spatial`) reuse those between frames and neighbours by reconnection. Per view: the
//! reservoirs are history, like a denoiser's.

mod reservoirs;
mod settings;
mod spatial;
mod temporal;

pub use reservoirs::ReservoirPair;
pub use settings::{
    ResamplingMode, ResamplingSettings, MAX_CANDIDATES, MAX_NEIGHBOURS, MAX_TEMPORAL_CAP,
    RADIUS_RANGE,
};

use crate::error::{Error, Result};
use crate::gpu_scene::GpuScene;
use crate::graph::FrameRecorder;
use crate::layouts::{GiReservoirGpu, ReservoirGpu};
use crate::passes::grid::GridFrame;
use crate::passes::Pass;
use crate::sampling::SamplingSpace;
use crate::vk::{Buffer, Context};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// A view's resampling: its passes, its reservoirs and how many frames they hold.
pub struct Resampling {
    pub settings: ResamplingSettings,
    temporal: Pass<temporal::Temporal>,
    spatial: Pass<spatial::Spatial>,
    reservoirs: ReservoirPair,
    gi: Option<GiResampling>,
    frames: u64,
    /// `GpuScene::lights_version` of the previous frame.
    lights_version: u64,
}

/// ReSTIR GI's two passes and reservoirs (`di+gi`).
struct GiResampling {
    temporal: Pass<temporal::GiTemporal>,
    spatial: Pass<spatial::GiSpatial>,
    reservoirs: ReservoirPair,
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
        let texels = grid.x as u64 * grid.y as u64;
        let buffer = |name: &str, texel_bytes: usize| {
            Buffer::new(
                ctx,
                name,
                texels * texel_bytes as u64,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::GpuOnly,
            )
        };
        let variant = space.shader_variant();
        let reservoir = std::mem::size_of::<ReservoirGpu>();
        let gi_reservoir = std::mem::size_of::<GiReservoirGpu>();
        let gi = match settings.mode.resamples_gi() {
            true => Some(GiResampling {
                temporal: Pass::new(ctx, variant)?,
                spatial: Pass::new(ctx, variant)?,
                reservoirs: ReservoirPair::new([
                    buffer("resampling.gi_reservoirs_a", gi_reservoir)?,
                    buffer("resampling.gi_reservoirs_b", gi_reservoir)?,
                ]),
            }),
            false => None,
        };
        Ok(Resampling {
            settings,
            temporal: Pass::new(ctx, variant)?,
            spatial: Pass::new(ctx, variant)?,
            reservoirs: ReservoirPair::new([
                buffer("resampling.reservoirs_a", reservoir)?,
                buffer("resampling.reservoirs_b", reservoir)?,
            ]),
            gi,
            frames: 0,
            lights_version: 0,
        })
    }

    /// GPU bytes of the reservoirs (last frame's and this frame's).
    pub fn history_bytes(&self) -> u64 {
        let gi = self.gi.as_ref().map_or(0, |gi| gi.reservoirs.bytes());
        self.reservoirs.bytes() + gi
    }

    /// Passes one frame records.
    pub fn passes(&self) -> u32 {
        if self.gi.is_some() {
            4
        } else {
            2
        }
    }

    /// Records the passes after the trace (`*_resampled` or `*_resampled_gi` variant) wrote
    /// `frame.gbuffer`; the
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
        // A rebuilt light table renumbers its entries (a light switched off leaves it) and
        // changes the light that reached the GI samples' secondary hits: neither reservoir's
        // history stands for this frame's lights.
        let fresh_start = self.frames == 0 || self.lights_version != scene.lights_version;
        self.lights_version = scene.lights_version;
        let (history, fresh) = self.reservoirs.for_frame(self.frames);
        self.temporal.record_temporal(
            rec,
            frame,
            shared,
            (
                temporal::Candidates::Drawn(self.settings.candidates),
                history,
                fresh,
                fresh_start,
            ),
            &self.settings,
        )?;
        self.spatial
            .record_spatial(rec, frame, shared, fresh, &self.settings)?;
        if let Some(gi) = &self.gi {
            let samples = frame.gbuffer.gi_samples.as_ref().ok_or_else(|| {
                Error::Invalid("ReSTIR GI needs the G-buffer's bounce samples".into())
            })?;
            let (history, fresh) = gi.reservoirs.for_frame(self.frames);
            gi.temporal.record_temporal(
                rec,
                frame,
                shared,
                (
                    temporal::Candidates::Traced(samples),
                    history,
                    fresh,
                    fresh_start,
                ),
                &self.settings,
            )?;
            gi.spatial
                .record_spatial(rec, frame, shared, fresh, &self.settings)?;
        }
        self.frames += 1;
        Ok(())
    }
}
