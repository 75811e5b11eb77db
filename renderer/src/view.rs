//! One view (an eye): its sampling space and everything that follows the space or carries
//! history between its frames — G-buffer, denoiser and TAA state, the way back to the screen,
//! the previous camera and gaze — plus, per frame slot, the small buffers the host writes or
//! reads (uniforms, counters, read-backs). The scene and the pipelines are shared by all views.

use crate::error::{Error, Result};
use crate::frame::{CameraPose, FrameStats, RenderSettings};
use crate::layouts::{FrameData, SamplingParams};
use crate::passes::denoise::{Denoiser, DenoiserSettings};
use crate::passes::grid::GBuffer;
use crate::passes::resampling::{Resampling, ResamplingMode};
use crate::passes::taa::{Taa, TaaMode};
use crate::passes::trace::{TracePass, RAY_COUNTERS};
use crate::sampling::{tile_count, SamplingSpace, TraceTiles, WayBack};
use crate::vk::{Buffer, Context, Image};
use crate::way_back::{self, WayBackPasses};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// What one view's frame in one slot owns on the host side: written before the submit, read
/// after the slot's fence.
pub(crate) struct ViewSlot {
    pub frame_data: Buffer,
    pub sampling: Buffer,
    /// The space's per-frame table (`SamplingSpace::sampling_table`), followed by the previous
    /// frame's (the denoisers reproject through the previous frame's space).
    pub sampling_table: Buffer,
    pub ray_counters: Buffer,
    /// This frame's trace tiles (`SamplingSpace::trace_tiles`): live, then idle.
    pub trace_tiles: Buffer,
    pub ldr_readback: Buffer,
    /// Made on the first frame that asks for it (`FrameInput::read_hdr` / `read_grid`): a viewer
    /// never pays for screen-sized HDR copies.
    pub hdr_readback: Option<Buffer>,
    pub grid_readback: Option<Buffer>,
}

impl ViewSlot {
    fn new(ctx: &Arc<Context>, space: &dyn SamplingSpace) -> Result<ViewSlot> {
        let screen = space.screen_size();
        let grid = space.grid_size();
        Ok(ViewSlot {
            frame_data: Buffer::with_data(
                ctx,
                "frame",
                &[FrameData::default()],
                vk::BufferUsageFlags::UNIFORM_BUFFER,
            )?,
            sampling: Buffer::with_data(
                ctx,
                "sampling",
                &[space.params()],
                vk::BufferUsageFlags::UNIFORM_BUFFER,
            )?,
            sampling_table: Buffer::texels(
                ctx,
                "sampling_table",
                &space.sampling_table().repeat(2),
            )?,
            ray_counters: Buffer::new(
                ctx,
                "ray_counters",
                (RAY_COUNTERS * 4) as u64,
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?,
            trace_tiles: Buffer::with_data(
                ctx,
                "trace_tiles",
                &vec![0u32; tile_count(grid).element_product() as usize],
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            ldr_readback: readback(ctx, "ldr_readback", screen.x as u64 * screen.y as u64 * 4)?,
            hdr_readback: None,
            grid_readback: None,
        })
    }

    pub fn stats(&self) -> Result<FrameStats> {
        let mut counters = [0u32; RAY_COUNTERS];
        self.ray_counters.read_into(&mut counters)?;
        Ok(FrameStats {
            samples_traced: counters[0] as u64,
            primary_rays: counters[0] as u64,
            shadow_rays: counters[1] as u64,
            continuation_rays: counters[2] as u64,
            samples_offscreen: counters[3] as u64,
            samples_culled: counters[4] as u64,
        })
    }
}

pub(crate) fn readback(ctx: &Arc<Context>, name: &str, bytes: u64) -> Result<Buffer> {
    Buffer::new(
        ctx,
        name,
        bytes,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )
}

pub struct View {
    pub space: Box<dyn SamplingSpace>,
    pub gbuffer: GBuffer,
    pub(crate) trace: TracePass,
    /// The tracer's gradient variant (its resampled one with resampling), which real-time frames
    /// use when the denoiser is A-SVGF (references keep `trace`).
    pub(crate) trace_gradients: Option<TracePass>,
    /// The tracer's resampled variant (without A-SVGF) and the resampling passes after it, which
    /// real-time frames use with `--resampling di` (references keep `trace`).
    pub(crate) trace_resampled: Option<TracePass>,
    pub(crate) resampling: Option<Resampling>,
    /// The passes of the space's way back to the screen.
    pub(crate) back: Box<dyn WayBackPasses>,
    /// Each texel's mean over the frame's samples, for spaces that trace several per texel.
    pub(crate) sample_mean: Option<Image>,
    pub(crate) ldr: Image,
    pub(crate) grid_ldr: Image,
    /// Reference accumulation target, made by the first `render_reference`.
    pub(crate) accum: Option<Image>,
    pub(crate) denoiser: Option<Box<dyn Denoiser>>,
    pub(crate) taa: Option<Taa>,
    pub(crate) prev_camera: Option<CameraPose>,
    /// The previous real-time frame's space (its gaze), for the denoiser's reprojection.
    pub(crate) prev_sampling: Option<SamplingParams>,
    pub(crate) slots: Vec<ViewSlot>,
    /// Host staging of the sampling table (this frame's, then the previous frame's), reused
    /// every frame (no per-frame allocation).
    pub(crate) table_rows: Vec<[f32; 4]>,
    /// The previous frame's table (`SamplingSpace::sampling_table` of `prev_sampling`).
    pub(crate) prev_table_rows: Vec<[f32; 4]>,
    /// The last frame's trace tiles, as written to its slot's `trace_tiles`.
    pub(crate) tiles: TraceTiles,
}

impl View {
    pub(crate) fn new(
        ctx: &Arc<Context>,
        space: Box<dyn SamplingSpace>,
        settings: &RenderSettings,
        slots: usize,
    ) -> Result<View> {
        let grid = space.grid_size();
        let screen = space.screen_size();
        let caps = space.capabilities();
        if !caps.temporal_filters
            && (settings.denoiser != DenoiserSettings::None || settings.taa != TaaMode::Off)
        {
            return Err(Error::Invalid(format!(
                "denoiser '{}' / TAA '{}': the {} space supports no denoiser or TAA {}",
                settings.denoiser.name(),
                settings.taa.name(),
                space.name(),
                caps.filters_note
            )));
        }
        // Screen-space TAA runs between the remap and the blur; where the sampling grid is the
        // screen, it is the sampling-grid filter.
        let remapped = caps.way_back == WayBack::Remap;
        let (grid_taa, screen_taa) = match (settings.taa, remapped) {
            (TaaMode::Screen(s), true) => (None, Some(s)),
            (mode, _) => (mode.settings().copied(), None),
        };
        let back = way_back::build(ctx, space.as_ref(), screen_taa, settings.blur.space)?;
        let denoiser = settings.denoiser.build(ctx, grid, space.shader_variant())?;
        let gradients = settings.denoiser.needs_gradients();
        let resampled = settings.resampling.mode != ResamplingMode::Off;
        let resampled_gi = settings.resampling.mode.resamples_gi();
        let resampling = match resampled {
            true => Some(Resampling::new(ctx, space.as_ref(), settings.resampling)?),
            false => None,
        };
        // The tracer's real-time variant: A-SVGF's gradients and resampling combine (with
        // resampling the gradient compares plain path estimates, trace.comp).
        let suffix = match (resampled, resampled_gi) {
            (false, _) => "",
            (true, false) => "_resampled",
            (true, true) => "_resampled_gi",
        };
        let variant = |gradients_suffix: &str| {
            let name = format!("{}{suffix}{gradients_suffix}", space.trace_variant());
            TracePass::new(ctx, &name)
        };
        let trace_gradients = match gradients {
            true => Some(variant("_gradients")?),
            false => None,
        };
        let trace_resampled = match resampled && !gradients {
            true => Some(variant("")?),
            false => None,
        };
        let mut gbuffer = if gradients {
            GBuffer::with_visibility(ctx, grid)?
        } else {
            GBuffer::new(ctx, grid)?
        };
        if resampled {
            gbuffer.add_primary_hit(ctx)?;
        }
        if resampled_gi {
            gbuffer.add_gi_samples(ctx)?;
        }
        let taa = match grid_taa {
            Some(s) => Some(Taa::new(ctx, grid, space.shader_variant(), s)?),
            None => None,
        };
        let slots = (0..slots)
            .map(|_| ViewSlot::new(ctx, space.as_ref()))
            .collect::<Result<Vec<_>>>()?;
        Ok(View {
            trace: TracePass::new(ctx, space.trace_variant())?,
            trace_gradients,
            trace_resampled,
            resampling,
            gbuffer,
            ldr: Image::new(ctx, "ldr", screen.x, screen.y, vk::Format::R8G8B8A8_UNORM)?,
            grid_ldr: Image::new(ctx, "grid_ldr", grid.x, grid.y, vk::Format::R8G8B8A8_UNORM)?,
            accum: None,
            sample_mean: match space.samples_per_texel() > 1 {
                true => Some(Image::new(
                    ctx,
                    "sample_mean",
                    grid.x,
                    grid.y,
                    vk::Format::R32G32B32A32_SFLOAT,
                )?),
                false => None,
            },
            back,
            denoiser,
            taa,
            prev_camera: None,
            prev_sampling: None,
            slots,
            table_rows: Vec::new(),
            prev_table_rows: Vec::new(),
            tiles: TraceTiles::default(),
            space,
        })
    }

    /// Writes this frame's trace tiles into `slot` (`cull`: samples far off the screen are not
    /// traced), for the trace's recording (`TileList::new`).
    pub(crate) fn write_trace_tiles(&mut self, slot: usize, cull: bool) -> Result<()> {
        self.space.trace_tiles(cull, &mut self.tiles);
        self.slots[slot].trace_tiles.write(self.tiles.packed())
    }

    /// Passes one frame of this view records at most (sizes the timestamp pool).
    pub(crate) fn max_passes(&self) -> u32 {
        let extra_samples = 2 * self.space.samples_per_texel();
        // 26: the idle tiles' clear is one of them.
        26 + extra_samples
            + self.denoiser.as_ref().map_or(0, |d| d.max_passes())
            + self.resampling.as_ref().map_or(0, |r| r.passes())
            + self.back.extra_passes()
    }

    /// GPU bytes of TAA history carried between frames (either mode; 0 when off).
    pub fn taa_history_bytes(&self) -> u64 {
        let grid = self.taa.as_ref().map_or(0, |t| t.history_bytes());
        grid + self.back.taa_history_bytes()
    }

    pub fn denoiser(&self) -> Option<&dyn Denoiser> {
        self.denoiser.as_deref()
    }

    pub fn taa(&self) -> Option<&Taa> {
        self.taa.as_ref()
    }

    /// The resampling passes' state, when `--resampling` is on.
    pub fn resampling(&self) -> Option<&Resampling> {
        self.resampling.as_ref()
    }

    /// The read-back buffers a frame in `slot` needs, made on first use.
    pub(crate) fn ensure_readbacks(
        &mut self,
        ctx: &Arc<Context>,
        slot: usize,
        hdr: bool,
        grid: bool,
    ) -> Result<()> {
        let screen = self.space.screen_size();
        let size = self.space.grid_size();
        let s = &mut self.slots[slot];
        if hdr && s.hdr_readback.is_none() {
            s.hdr_readback = Some(readback(
                ctx,
                "hdr_readback",
                screen.x as u64 * screen.y as u64 * 16,
            )?);
        }
        if grid && s.grid_readback.is_none() {
            s.grid_readback = Some(readback(
                ctx,
                "grid_readback",
                size.x as u64 * size.y as u64 * 4,
            )?);
        }
        Ok(())
    }
}
