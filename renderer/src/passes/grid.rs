//! The sampling grid's per-frame state that the tracer writes and the passes after it read: the
//! G-buffer, the trace's tile list, and the frame context every grid pass takes (`GridFrame`).

use crate::error::Result;
use crate::graph::{write_image, Bind};
use crate::layouts::{SamplingParams, WORKGROUP_2D};
use crate::sampling::{SamplingSpace, TraceTiles};
use crate::vk::{Buffer, Context, Image};
use ash::vk;
use glam::{UVec2, Vec3};
use std::sync::Arc;

/// Everything the tracer writes per sample, sized to the sampling grid. Denoisers read these.
pub struct GBuffer {
    pub size: UVec2,
    /// Full radiance (what a viewer sees without a denoiser).
    pub color: Image,
    /// Radiance divided by albedo (demodulated; exactly `color / albedo`); w: the primary hit's
    /// roughness, textures applied (cross-eye reuse's test of view dependence).
    pub radiance: Image,
    pub albedo: Image,
    /// Shading normal (xyz) and linear view depth (w, 0 where nothing was hit).
    pub normal_depth: Image,
    /// Hit position relative to the camera (xyz) and the depth change per grid texel (w; per
    /// pixel in Cartesian space, per VP texel's screen footprint in Visual-Polar space).
    pub position: Image,
    /// x: triangle index + 1 (0: miss); y: material | mesh << 16.
    pub ids: Image,
    /// Previous frame's screen position of the surface (−1: none).
    pub motion: Image,
    /// Only for A-SVGF (`GBuffer::with_visibility`; written by the gradient kernel variants):
    /// x, y barycentrics of the hit (float bits), z the RNG state after the jitter draw — what
    /// re-shading exactly this sample's path next frame needs besides `ids` — and w 1 where the
    /// sample was itself a gradient sample (not projected again).
    pub visibility: Option<Image>,
    /// Only for resampling (`GBuffer::add_primary_hit`; written by the `*_resampled` kernel
    /// variants): the primary hit's barycentrics (x, y) and ray-cone width (z), from which the
    /// resampling passes re-fetch the surface the tracer shaded.
    pub primary_hit: Option<Image>,
    /// Only for ReSTIR GI (`GBuffer::add_gi_samples`; written by the `*_resampled_gi` kernel
    /// variants): per texel the bounce's secondary hit and the radiance gathered there
    /// (`GiSampleGpu`), which the tracer leaves out of `color`.
    pub gi_samples: Option<Buffer>,
}

impl GBuffer {
    pub fn new(ctx: &Arc<Context>, size: UVec2) -> Result<GBuffer> {
        let image = |name: &str, format| Image::new(ctx, name, size.x, size.y, format);
        Ok(GBuffer {
            size,
            color: image("gbuffer.color", vk::Format::R32G32B32A32_SFLOAT)?,
            radiance: image("gbuffer.radiance", vk::Format::R32G32B32A32_SFLOAT)?,
            albedo: image("gbuffer.albedo", vk::Format::R16G16B16A16_SFLOAT)?,
            normal_depth: image("gbuffer.normal_depth", vk::Format::R32G32B32A32_SFLOAT)?,
            position: image("gbuffer.position", vk::Format::R32G32B32A32_SFLOAT)?,
            ids: image("gbuffer.ids", vk::Format::R32G32_UINT)?,
            motion: image("gbuffer.motion", vk::Format::R32G32_SFLOAT)?,
            visibility: None,
            primary_hit: None,
            gi_samples: None,
        })
    }

    /// The images every sample writes, bound by their kernels' names (trace.comp, trace_clear.comp).
    pub fn write_binds(&self) -> [Bind<'_>; 7] {
        [
            write_image("out_color", &self.color),
            write_image("out_radiance", &self.radiance),
            write_image("out_albedo", &self.albedo),
            write_image("out_normal_depth", &self.normal_depth),
            write_image("out_position", &self.position),
            write_image("out_ids", &self.ids),
            write_image("out_motion", &self.motion),
        ]
    }

    /// Adds the primary-hit image the resampling passes read.
    pub fn add_primary_hit(&mut self, ctx: &Arc<Context>) -> Result<()> {
        self.primary_hit = Some(Image::new(
            ctx,
            "gbuffer.primary_hit",
            self.size.x,
            self.size.y,
            vk::Format::R32G32B32A32_SFLOAT,
        )?);
        Ok(())
    }

    /// Adds the bounce samples ReSTIR GI's passes read.
    pub fn add_gi_samples(&mut self, ctx: &Arc<Context>) -> Result<()> {
        let bytes = self.size.x as u64
            * self.size.y as u64
            * std::mem::size_of::<crate::layouts::GiSampleGpu>() as u64;
        self.gi_samples = Some(Buffer::new(
            ctx,
            "gbuffer.gi_samples",
            bytes,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            gpu_allocator::MemoryLocation::GpuOnly,
        )?);
        Ok(())
    }

    /// A G-buffer with the visibility image the A-SVGF gradient samples are projected from.
    pub fn with_visibility(ctx: &Arc<Context>, size: UVec2) -> Result<GBuffer> {
        let mut g = GBuffer::new(ctx, size)?;
        g.visibility = Some(Image::new(
            ctx,
            "gbuffer.visibility",
            size.x,
            size.y,
            vk::Format::R32G32B32A32_UINT,
        )?);
        Ok(g)
    }
}

/// What the `*_gradients` kernel variants read and write besides the G-buffer (A-SVGF).
#[derive(Clone, Copy)]
pub struct GradientTargets<'a> {
    /// The forward-projected samples (`AsvgfGradientSample` per 3×3 stratum); the tracer adds
    /// this frame's luminance.
    pub samples: &'a Buffer,
    /// Per stratum: δ, max f, 1 where a sample was re-shaded (zeros elsewhere: the forward
    /// projection clears it).
    pub gradient: &'a Image,
}

/// This frame's trace tiles on the GPU (`SamplingSpace::trace_tiles`): `live` tiles then `idle`
/// ones in `buffer`, and the samples the idle tiles hold (all culled).
#[derive(Clone, Copy)]
pub struct TileList<'a> {
    pub buffer: &'a Buffer,
    pub live: u32,
    pub idle: u32,
    pub culled_samples: u32,
}

impl<'a> TileList<'a> {
    /// `tiles` as written into `buffer`.
    pub fn new(buffer: &'a Buffer, tiles: &TraceTiles) -> TileList<'a> {
        TileList {
            buffer,
            live: tiles.live.len() as u32,
            idle: tiles.idle.len() as u32,
            culled_samples: tiles.culled_samples,
        }
    }

    /// The threads of a dispatch over the live tiles (one workgroup each; shaders/common/tiles.glsl).
    pub fn live_threads(&self) -> [u32; 3] {
        [self.live * WORKGROUP_2D, WORKGROUP_2D, 1]
    }

    /// The threads of a dispatch over the idle tiles (the list's entries from `live` on).
    pub fn idle_threads(&self) -> [u32; 3] {
        [self.idle * WORKGROUP_2D, WORKGROUP_2D, 1]
    }
}

/// A space's tile list with a buffer of its own, for running the grid's passes outside a view
/// (tests, tools); a view keeps one per frame slot.
pub struct OwnedTileList {
    pub buffer: Buffer,
    pub tiles: TraceTiles,
}

impl OwnedTileList {
    /// `space`'s tiles for its current gaze (`cull`: samples far off the screen are not traced).
    pub fn new(ctx: &Arc<Context>, space: &dyn SamplingSpace, cull: bool) -> Result<OwnedTileList> {
        let mut tiles = TraceTiles::default();
        space.trace_tiles(cull, &mut tiles);
        let buffer = Buffer::with_data(
            ctx,
            "tiles",
            tiles.packed(),
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        Ok(OwnedTileList { buffer, tiles })
    }

    pub fn list(&self) -> TileList<'_> {
        TileList::new(&self.buffer, &self.tiles)
    }
}

/// One frame of the sampling grid as the passes from the tracer on read it: the G-buffer, the
/// frame's buffers, this frame's space and the previous one's, the space's table and the trace's
/// tiles. A view makes one per frame; every grid pass (trace, denoisers, TAA) takes it.
#[derive(Clone, Copy)]
pub struct GridFrame<'a> {
    /// What the tracer writes this frame (before the trace: last frame's, which A-SVGF
    /// projects).
    pub gbuffer: &'a GBuffer,
    /// The frame's uniform buffer (`FrameData`: this camera and the previous one).
    pub frame_data: &'a Buffer,
    /// The space's uniform buffer (`current`, binding `sampling`).
    pub sampling: &'a Buffer,
    /// This frame's space (its gaze) and the previous frame's; `None` when there is no usable
    /// previous frame, which drops all history.
    pub current: SamplingParams,
    pub previous: Option<SamplingParams>,
    /// The view's sampling table: this frame's (`SamplingSpace::sampling_table`) followed by the
    /// previous frame's of the same length (the screen-clipped layout's kernels read both
    /// frames' arcs from it).
    pub sampling_table: &'a Buffer,
    /// The trace's tiles this frame: passes that work per texel run over the live ones (the
    /// idle ones hold no traced sample) and write what later frames read of the idle ones.
    pub tiles: TileList<'a>,
    /// This frame's camera position in world space (the G-buffer's positions are relative to
    /// it; BMFR accumulates positions across frames).
    pub camera_origin: Vec3,
    /// The scene's materials (`MaterialGpu`; BMFR keeps emitters out of its fits).
    pub materials: &'a Buffer,
}
