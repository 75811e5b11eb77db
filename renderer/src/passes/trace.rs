//! The path-tracing pass: one sample per sampling-grid texel, writing the per-sample G-buffer.
//! Its `*_gradients` kernel variants also re-shade A-SVGF's gradient samples (denoise/asvgf).

use super::push_bytes;
use super::trace_clear::TraceClearPass;
use crate::error::Result;
use crate::gpu_scene::GpuScene;
use crate::graph::{read_buffer, read_texels, write_buffer, write_image, Bind, FrameRecorder};
use crate::layouts::{TracePush, WORKGROUP_2D};
use crate::sampling::{SamplingSpace, TraceTiles};
use crate::vk::{Buffer, ComputePipeline, Context, Image};
use ash::vk;
use glam::{UVec2, UVec4};
use std::sync::Arc;

/// Everything the tracer writes per sample, sized to the sampling grid. Denoisers read these.
pub struct GBuffer {
    pub size: UVec2,
    /// Full radiance (what a viewer sees without a denoiser).
    pub color: Image,
    /// Radiance divided by albedo (demodulated; exactly `color / albedo`).
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

pub struct TracePass {
    pipeline: std::sync::Arc<ComputePipeline>,
    clear: TraceClearPass,
}

/// Counters the trace kernel fills (one u32 each): primary, shadow and continuation rays, and
/// traced samples whose screen position lies off the screen, samples culled off the screen.
pub const RAY_COUNTERS: usize = 5;

impl TracePass {
    pub fn new(ctx: &Arc<Context>, sampling_variant: &str) -> Result<TracePass> {
        let shader = format!("passes/trace.{sampling_variant}");
        Ok(TracePass {
            pipeline: ComputePipeline::shared(
                ctx,
                &shader,
                std::mem::size_of::<TracePush>() as u32,
            )?,
            clear: TraceClearPass::new(ctx)?,
        })
    }

    /// Records one sample per grid texel. `sample_index` decorrelates several samples of one
    /// frame (reference accumulation); real-time frames use 0. `sampling_table` holds the space's
    /// `SamplingSpace::sampling_table` (Visual-Polar: its per-column arcs). `gradients`: A-SVGF's,
    /// for the `*_gradients` variants (which also write `out.visibility`). Only `tiles`' live tiles
    /// are traced; its idle ones are cleared to "not traced".
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        scene: &GpuScene,
        frame: &Buffer,
        sampling: &Buffer,
        sampling_table: &Buffer,
        ray_counters: &Buffer,
        out: &GBuffer,
        tiles: &TileList,
        sample_index: u32,
        gradients: Option<GradientTargets>,
    ) -> Result<()> {
        // The idle tiles hold the same not-traced values for every sample of a frame (or of a
        // reference): cleared, and their culled samples counted, with the first.
        if sample_index == 0 {
            self.clear.record(rec, tiles, ray_counters, out)?;
        }
        if tiles.live == 0 {
            return Ok(());
        }
        let s = scene.binds();
        // A fixed array sliced to what this kernel binds: no host allocation per frame.
        let gradient_binds = match (gradients, &out.visibility) {
            (Some(g), Some(visibility)) => Some([
                write_buffer("gradient_samples", g.samples),
                write_image("out_gradient", g.gradient),
                write_image("out_visibility", visibility),
            ]),
            _ => None,
        };
        let extra = gradient_binds.unwrap_or([s[0]; 3]);
        let g = out.write_binds();
        let binds = [
            s[0],
            s[1],
            s[2],
            s[3],
            s[4],
            s[5],
            s[6],
            s[7],
            s[8],
            s[9],
            read_buffer("frame", frame),
            read_buffer("sampling", sampling),
            read_texels("sampling_table", sampling_table),
            write_buffer("ray_counters", ray_counters),
            g[0],
            g[1],
            g[2],
            g[3],
            g[4],
            g[5],
            g[6],
            read_buffer("tiles", tiles.buffer),
            extra[0],
            extra[1],
            extra[2],
        ];
        let binds = &binds[..if gradient_binds.is_some() {
            binds.len()
        } else {
            binds.len() - 3
        }];
        // y = 0: the cameras' column base, a value lavapipe cannot fold (see trace.comp).
        let push = TracePush {
            config: UVec4::new(sample_index, 0, 0, 0),
        };
        rec.dispatch(
            "trace",
            &self.pipeline,
            binds,
            push_bytes(&push),
            tiles.live_threads(),
        )
    }
}
