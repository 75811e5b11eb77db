//! Composes a frame: sampling space → trace → denoiser (optional, in the sampling grid) → screen
//! image (Visual-Polar: φ-mips, remap, foveated blur) → tonemap → read-back.
//! Also renders converged references by accumulating many samples.

use crate::error::{Error, Result};
use crate::gpu_scene::GpuScene;
use crate::graph::{FrameRecorder, PassTiming};
use crate::layouts::{FrameData, SamplingParams, FRAME_FLAG_HALTON_JITTER, FRAME_FLAG_REFERENCE};
use crate::passes::accumulate::AccumulatePass;
use crate::passes::denoise::taa::{Taa, TaaMode};
use crate::passes::denoise::taa_screen::ScreenTaaFrame;
use crate::passes::denoise::{DenoiseFrame, DenoiseScene, Denoiser, DenoiserSettings};
use crate::passes::tonemap::{TonemapPass, ToneCurve};
use crate::passes::trace::{GBuffer, TracePass, RAY_COUNTERS};
use crate::sampling::SamplingSpace;
use crate::to_screen::{BlurSettings, ToScreen};
use crate::scene::{Camera, Scene};
use crate::vk::{Buffer, Context, Image};
use ash::vk;
use glam::{Mat4, UVec4, Vec2, Vec4};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// The real-time path: primary ray, one indirect bounce, next-event estimation at both hits.
pub const REALTIME_MAX_DEPTH: u32 = 3;
/// Passes one reference submission may hold (trace + accumulate per sample).
const REFERENCE_SAMPLES_PER_SUBMIT: u32 = 8;

/// A pinhole camera: rigid pose and the tangents of its four half-angles (left/down negative).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    pub world_from_view: Mat4,
    pub fov_tan: Vec4,
}

impl CameraPose {
    /// A glTF camera fitted to an output size: `yfov` is kept and the horizontal extent follows
    /// the output's aspect ratio, so pixels stay square.
    pub fn from_scene_camera(camera: &Camera, width: u32, height: u32) -> CameraPose {
        let ty = (camera.yfov * 0.5).tan();
        let tx = ty * width as f32 / height as f32;
        CameraPose { world_from_view: camera.world_from_view, fov_tan: Vec4::new(-tx, tx, -ty, ty) }
    }
}

#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    pub max_depth: u32,
    pub seed: u32,
    pub exposure: f32,
    pub tone_curve: ToneCurve,
    /// Foveated blur after the remap (Visual-Polar only).
    pub blur: BlurSettings,
    /// Denoiser between the tracer and the screen (fixed for the renderer's life: it owns state).
    pub denoiser: DenoiserSettings,
    /// TAA after the denoiser (fixed for the renderer's life, like the denoiser); when on, the
    /// tracer jitters by its Halton sequence instead of the RNG.
    pub taa: TaaMode,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            max_depth: REALTIME_MAX_DEPTH,
            seed: 1,
            exposure: 1.0,
            tone_curve: ToneCurve::Aces,
            blur: BlurSettings::default(),
            denoiser: DenoiserSettings::None,
            taa: TaaMode::Off,
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub struct FrameInput {
    pub camera: CameraPose,
    pub frame_index: u32,
    /// Gaze point in screen pixels; `None` keeps the space's current gaze.
    pub gaze: Option<Vec2>,
    /// Also copy the linear screen image back (EXR output).
    pub read_hdr: bool,
    /// Also tonemap the sampling-grid image and copy it back (`read_grid_ldr`; debug views).
    pub read_grid: bool,
}

/// Exact counts for one frame (from the GPU's own counters).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameStats {
    pub samples_traced: u64,
    pub primary_rays: u64,
    pub shadow_rays: u64,
    pub continuation_rays: u64,
    /// Traced samples whose screen position lies off the screen (Visual-Polar covers the r_max
    /// circle; always 0 for Cartesian).
    pub samples_offscreen: u64,
}

impl FrameStats {
    pub fn rays_traced(&self) -> u64 {
        self.primary_rays + self.shadow_rays + self.continuation_rays
    }
}

pub struct Renderer {
    ctx: Arc<Context>,
    pub scene: GpuScene,
    space: Box<dyn SamplingSpace>,
    pub settings: RenderSettings,
    frame_data: Buffer,
    sampling: Buffer,
    /// The space's per-frame table (`SamplingSpace::sampling_table`), read by the trace and the
    /// Visual-Polar passes back to the screen.
    sampling_table: Buffer,
    /// Host staging of `sampling_table`, reused every frame (no per-frame allocation).
    sampling_table_rows: Vec<[f32; 4]>,
    ray_counters: Buffer,
    trace: TracePass,
    /// The tracer's gradient variant, which real-time frames use when the denoiser is A-SVGF
    /// (references keep `trace`).
    trace_gradients: Option<TracePass>,
    accumulate: AccumulatePass,
    tonemap: TonemapPass,
    pub gbuffer: GBuffer,
    accum: Image,
    /// Visual-Polar spaces only: the way back to the screen.
    to_screen: Option<ToScreen>,
    ldr: Image,
    ldr_readback: Buffer,
    hdr_readback: Buffer,
    grid_ldr: Image,
    grid_readback: Buffer,
    /// Per-eye denoiser state (`settings.denoiser`).
    denoiser: Option<Denoiser>,
    /// Per-eye TAA state (`settings.taa`).
    taa: Option<Taa>,
    recorder: FrameRecorder,
    prev_camera: Option<CameraPose>,
    /// The previous real-time frame's space (its gaze), for the denoiser's reprojection.
    prev_sampling: Option<SamplingParams>,
}

impl Renderer {
    pub fn new(ctx: &Arc<Context>, scene: &Scene, space: Box<dyn SamplingSpace>, settings: RenderSettings) -> Result<Renderer> {
        let gpu_scene = GpuScene::upload(ctx, scene)?;
        Renderer::with_gpu_scene(ctx, gpu_scene, space, settings)
    }

    pub fn with_gpu_scene(ctx: &Arc<Context>, scene: GpuScene, space: Box<dyn SamplingSpace>, settings: RenderSettings) -> Result<Renderer> {
        if settings.max_depth == 0 {
            return Err(Error::Invalid("max depth must be at least 1 (1 = emission seen directly)".into()));
        }
        let grid = space.grid_size();
        let screen = space.screen_size();
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let uniform = vk::BufferUsageFlags::UNIFORM_BUFFER;
        let readback = |name: &str, bytes: u64| {
            Buffer::new(ctx, name, bytes, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)
        };
        let pixels = screen.x as u64 * screen.y as u64;
        // Screen-space TAA runs between the remap and the blur; for Cartesian the sampling grid
        // is the screen, and it is the sampling-grid filter.
        let (grid_taa, screen_taa) = match (settings.taa, space.visual_polar()) {
            (TaaMode::Screen(s), Some(_)) => (None, Some(s)),
            (mode, _) => (mode.settings().copied(), None),
        };
        let to_screen = match space.visual_polar() {
            Some(_) => Some(ToScreen::new(ctx, grid, screen, screen_taa)?),
            None => None,
        };
        let denoiser = Denoiser::new(ctx, &settings.denoiser, grid, space.shader_variant())?;
        let gradients = settings.denoiser.needs_gradients();
        let trace_gradients = match (gradients, space.trace_variant()) {
            (false, _) => None,
            (true, "visual_polar_clipped") => {
                return Err(Error::Invalid(format!(
                    "denoiser '{}' does not support the screen-clipped Visual-Polar layout (use layout = \"paper\")",
                    settings.denoiser.name()
                )))
            }
            (true, variant) => Some(TracePass::new(ctx, &format!("{variant}_gradients"))?),
        };
        let denoiser_passes = denoiser.as_ref().map_or(0, |d| d.max_passes());
        let taa = match grid_taa {
            Some(s) => Some(Taa::new(ctx, grid, space.shader_variant(), s)?),
            None => None,
        };
        Ok(Renderer {
            frame_data: Buffer::with_data(ctx, "frame", &[FrameData::default()], uniform)?,
            sampling: Buffer::with_data(ctx, "sampling", &[space.params()], uniform)?,
            sampling_table: Buffer::texels(ctx, "sampling_table", &space.sampling_table())?,
            sampling_table_rows: Vec::new(),
            ray_counters: Buffer::new(
                ctx,
                "ray_counters",
                (RAY_COUNTERS * 4) as u64,
                storage | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?,
            trace: TracePass::new(ctx, space.trace_variant())?,
            trace_gradients,
            accumulate: AccumulatePass::new(ctx)?,
            tonemap: TonemapPass::new(ctx)?,
            gbuffer: if gradients { GBuffer::with_visibility(ctx, grid)? } else { GBuffer::new(ctx, grid)? },
            accum: Image::new(ctx, "accum", screen.x, screen.y, vk::Format::R32G32B32A32_SFLOAT)?,
            ldr: Image::new(ctx, "ldr", screen.x, screen.y, vk::Format::R8G8B8A8_UNORM)?,
            ldr_readback: readback("ldr_readback", pixels * 4)?,
            hdr_readback: readback("hdr_readback", pixels * 16)?,
            grid_ldr: Image::new(ctx, "grid_ldr", grid.x, grid.y, vk::Format::R8G8B8A8_UNORM)?,
            grid_readback: readback("grid_readback", grid.x as u64 * grid.y as u64 * 4)?,
            to_screen,
            recorder: FrameRecorder::new(ctx, 2 * REFERENCE_SAMPLES_PER_SUBMIT + 25 + denoiser_passes)?,
            denoiser,
            taa,
            prev_camera: None,
            prev_sampling: None,
            ctx: ctx.clone(),
            scene,
            space,
            settings,
        })
    }

    pub fn space(&self) -> &dyn SamplingSpace {
        self.space.as_ref()
    }

    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }

    /// Scales a material's emission at run time (`GpuScene::set_emission_scale`; `scene` is the
    /// scene this renderer was built from): a light switched off, dimmed or back on.
    pub fn set_emission_scale(&mut self, scene: &Scene, material: usize, scale: f32) -> Result<()> {
        self.scene.set_emission_scale(&self.ctx, scene, material, scale)
    }

    /// The denoiser and its state, when `settings.denoiser` names one.
    pub fn denoiser(&self) -> Option<&Denoiser> {
        self.denoiser.as_ref()
    }

    /// GPU time of each pass of the last submission.
    pub fn timings(&self) -> &[PassTiming] {
        self.recorder.timings()
    }

    /// The sampling-grid TAA state, when `settings.taa` runs in the grid.
    pub fn taa(&self) -> Option<&Taa> {
        self.taa.as_ref()
    }

    /// GPU bytes of TAA history carried between frames (either mode; 0 when off).
    pub fn taa_history_bytes(&self) -> u64 {
        let grid = self.taa.as_ref().map_or(0, |t| t.history_bytes());
        let screen = self.to_screen.as_ref().and_then(|s| s.taa.as_ref()).map_or(0, |t| t.history_bytes());
        grid + screen
    }

    fn write_frame_data(&self, camera: &CameraPose, frame_index: u32, max_depth: u32, flags: u32, jitter: Vec2) -> Result<()> {
        let screen = self.space.screen_size().as_vec2();
        let prev = self.prev_camera.unwrap_or(*camera);
        let data = FrameData {
            world_from_view: camera.world_from_view,
            prev_view_from_world: prev.world_from_view.inverse(),
            fov_tan: camera.fov_tan,
            prev_fov_tan: prev.fov_tan,
            screen: Vec4::new(screen.x, screen.y, 1.0 / screen.x, 1.0 / screen.y),
            frame: UVec4::new(frame_index, self.settings.seed, max_depth, flags),
            counts: UVec4::new(
                self.scene.light_count,
                self.scene.triangle_count,
                self.scene.material_count,
                self.scene.texture_count,
            ),
            scene_sphere: self.scene.bounding_sphere(),
            jitter: jitter.extend(0.0).extend(0.0),
        };
        self.frame_data.write(&[data])
    }

    /// Renders one real-time frame into the screen image and reads the tonemapped result back.
    pub fn render_frame(&mut self, input: &FrameInput) -> Result<FrameStats> {
        if let Some(gaze) = input.gaze {
            self.space.set_gaze(gaze)?;
        }
        let jitter = self.settings.taa.settings().map(|t| t.jitter(input.frame_index));
        let flags = if jitter.is_some() { FRAME_FLAG_HALTON_JITTER } else { 0 };
        self.write_frame_data(&input.camera, input.frame_index, self.settings.max_depth, flags, jitter.unwrap_or(Vec2::ZERO))?;
        let space = self.space.params();
        self.sampling.write(&[space])?;
        self.space.write_sampling_table(&mut self.sampling_table_rows);
        self.sampling_table.write(&self.sampling_table_rows)?;
        let rec = &mut self.recorder;
        rec.begin()?;
        rec.fill_buffer("clear_counters", &self.ray_counters, 0)?;
        // Denoisers work in the sampling grid (Cartesian samples are the screen).
        let denoise_frame = DenoiseFrame { current: space, previous: self.prev_sampling };
        if let Some(d) = &mut self.denoiser {
            d.record_before_trace(rec, &self.gbuffer, &denoise_frame, &self.frame_data)?;
        }
        let gradients = self.denoiser.as_ref().and_then(|d| d.gradient_targets());
        let trace = self.trace_gradients.as_ref().unwrap_or(&self.trace);
        trace.record(rec, &self.scene, &self.frame_data, &self.sampling, &self.sampling_table, &self.ray_counters, &self.gbuffer, 0, gradients)?;
        let denoised = match &mut self.denoiser {
            Some(d) => {
                let scene = DenoiseScene { camera_origin: input.camera.world_from_view.w_axis.truncate(), materials: &self.scene.materials };
                d.record(rec, &self.gbuffer, &denoise_frame, &scene)?
            }
            None => &self.gbuffer.color,
        };
        let grid_hdr = match (&mut self.taa, jitter) {
            (Some(taa), Some(jitter)) => taa.record(rec, &self.gbuffer, denoised, &denoise_frame, jitter)?,
            _ => denoised,
        };
        let screen_taa = jitter.map(|jitter| ScreenTaaFrame {
            frame_data: &self.frame_data,
            gbuffer: &self.gbuffer,
            space: &denoise_frame.current,
            has_previous: denoise_frame.previous.is_some(),
            jitter,
        });
        let screen_hdr = match (&mut self.to_screen, self.space.visual_polar()) {
            (Some(to_screen), Some(vp)) => to_screen.record(rec, vp, &self.sampling_table, grid_hdr, &self.settings.blur, screen_taa.as_ref())?,
            _ => grid_hdr,
        };
        let (exposure, curve) = (self.settings.exposure, self.settings.tone_curve);
        self.tonemap.record(rec, "tonemap", screen_hdr, &self.ldr, exposure, curve)?;
        rec.copy_image_to_buffer("readback", &self.ldr, &self.ldr_readback)?;
        if input.read_hdr {
            rec.copy_image_to_buffer("readback_hdr", screen_hdr, &self.hdr_readback)?;
        }
        if input.read_grid {
            self.tonemap.record(rec, "tonemap_grid", grid_hdr, &self.grid_ldr, exposure, curve)?;
            rec.copy_image_to_buffer("readback_grid", &self.grid_ldr, &self.grid_readback)?;
        }
        rec.submit_and_wait()?;
        self.prev_camera = Some(input.camera);
        self.prev_sampling = Some(space);
        let mut counters = [0u32; RAY_COUNTERS];
        self.ray_counters.read_into(&mut counters)?;
        Ok(FrameStats {
            samples_traced: counters[0] as u64,
            primary_rays: counters[0] as u64,
            shadow_rays: counters[1] as u64,
            continuation_rays: counters[2] as u64,
            samples_offscreen: counters[3] as u64,
        })
    }

    /// The last frame's tonemapped pixels, RGBA8, rows top to bottom.
    pub fn read_ldr(&self, out: &mut Vec<u8>) -> Result<()> {
        out.resize(self.ldr_readback.size as usize, 0);
        self.ldr_readback.read_into(out)
    }

    /// The last frame's tonemapped sampling-grid image (`FrameInput::read_grid`), RGBA8.
    pub fn read_grid_ldr(&self, out: &mut Vec<u8>) -> Result<()> {
        out.resize(self.grid_readback.size as usize, 0);
        self.grid_readback.read_into(out)
    }

    /// The last frame's (or reference's) linear screen image, RGBA32F.
    pub fn read_hdr(&self, out: &mut Vec<[f32; 4]>) -> Result<()> {
        out.resize(self.hdr_readback.size as usize / 16, [0.0; 4]);
        self.hdr_readback.read_into(out)
    }

    /// Converged linear radiance: the mean of `spp` samples per pixel with paths of up to
    /// `max_depth` vertices. `progress` gets the number of samples done after each submission.
    pub fn render_reference(
        &mut self,
        camera: &CameraPose,
        spp: u32,
        max_depth: u32,
        mut progress: impl FnMut(u32),
    ) -> Result<Vec<[f32; 4]>> {
        if spp == 0 || max_depth == 0 {
            return Err(Error::Invalid("reference needs spp ≥ 1 and max depth ≥ 1".into()));
        }
        if self.space.grid_size() != self.space.screen_size() {
            return Err(Error::Invalid("references are rendered in Cartesian space".into()));
        }
        // The G-buffer is overwritten and the previous camera forgotten: no history survives.
        self.prev_camera = None;
        self.prev_sampling = None;
        self.write_frame_data(camera, 0, max_depth, FRAME_FLAG_REFERENCE, Vec2::ZERO)?;
        self.sampling.write(&[self.space.params()])?;
        let mut done = 0;
        while done < spp {
            let batch = (spp - done).min(REFERENCE_SAMPLES_PER_SUBMIT);
            let rec = &mut self.recorder;
            rec.begin()?;
            for s in done..done + batch {
                self.trace.record(rec, &self.scene, &self.frame_data, &self.sampling, &self.sampling_table, &self.ray_counters, &self.gbuffer, s, None)?;
                self.accumulate.record(rec, &self.gbuffer.color, &self.accum, s)?;
            }
            if done + batch == spp {
                rec.copy_image_to_buffer("readback_hdr", &self.accum, &self.hdr_readback)?;
            }
            rec.submit_and_wait()?;
            done += batch;
            progress(done);
        }
        let mut out = Vec::new();
        self.read_hdr(&mut out)?;
        Ok(out)
    }
}
