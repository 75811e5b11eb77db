//! Composes a frame: sampling space → trace → resampling (optional) → denoiser (optional, in the
//! sampling grid) → screen image (Visual-Polar: φ-mips, remap, foveated blur) for every view → one
//! exposure metered over all views → tonemap → read-back.
//! Also renders converged references by accumulating many samples.

use crate::error::{Error, Result};
use crate::frame::{
    CameraPose, CrossEyeReuse, EnvironmentSampling, FrameInput, FrameStats, FrameTarget,
    OffscreenSamples, RenderSettings, StereoNoise, TextureLod, ViewInput, MAX_VIEWS,
    SURFACE_CELL_RANGE,
};
use crate::frames::FrameRing;
use crate::gpu_scene::GpuScene;
use crate::graph::{ExternalImage, FrameRecorder, PassTiming, SubmitSync};
use crate::layouts::{
    FrameData, FRAME_FLAG_ALPHA_MASK, FRAME_FLAG_CULL_OFFSCREEN, FRAME_FLAG_HALTON_JITTER,
    FRAME_FLAG_REFERENCE, FRAME_FLAG_SURFACE_NOISE, FRAME_FLAG_TEXTURE_LOD,
};
use crate::passes::accumulate::AccumulatePass;
use crate::passes::cross_eye::CrossEye;
use crate::passes::denoise::Denoiser;
use crate::passes::exposure::{Exposure, ExposurePass};
use crate::passes::grid::{GridFrame, TileList};
use crate::passes::resampling::ResamplingMode;
use crate::passes::taa::Taa;
use crate::passes::tonemap::{LdrTarget, ToneTarget, TonemapPass};
use crate::sampling::SamplingSpace;
use crate::scene::Scene;
use crate::view::View;
use crate::vk::{Buffer, Context, Image};
use crate::way_back::{ScreenOut, WayBackFrame};
use ash::vk;
use glam::{UVec2, UVec4, Vec2, Vec4};
use std::sync::Arc;

/// A view's `GridFrame` for this slot (a macro, not a function: `record_samples` and
/// `record_filters` hold the view's denoiser mutably beside it).
macro_rules! grid_frame {
    ($view:expr, $slot:expr, $scene:expr, $camera:expr) => {
        GridFrame {
            gbuffer: &$view.gbuffer,
            frame_data: &$slot.frame_data,
            sampling: &$slot.sampling,
            current: $view.space.params(),
            previous: $view.prev_sampling,
            sampling_table: &$slot.sampling_table,
            tiles: TileList::new(&$slot.trace_tiles, &$view.tiles),
            camera_origin: $camera.world_from_view.w_axis.truncate(),
            materials: &$scene.materials,
        }
    };
}

/// Passes one reference submission may hold (trace + accumulate per sample).
const REFERENCE_SAMPLES_PER_SUBMIT: u32 = 8;

/// What one view's frame uniforms (`FrameData`) are made from besides the scene and settings.
#[derive(Clone, Copy)]
struct FrameUniforms {
    camera: CameraPose,
    index: u32,
    max_depth: u32,
    /// `FRAME_FLAG_*`.
    flags: u32,
    /// The TAA jitter inside the texel (zero without TAA).
    jitter: Vec2,
}

/// The real-time engine: one scene upload and one set of pipelines shared by every view, each
/// view with its own space and history, all views of a frame recorded into one command buffer
/// and submitted once, frames kept in flight on a ring of slots (`frames`).
pub struct Renderer {
    ctx: Arc<Context>,
    pub scene: GpuScene,
    pub settings: RenderSettings,
    views: Vec<View>,
    /// Cross-eye reuse between the two views (`RenderSettings::cross_eye_reuse` with two views).
    cross_eye: Option<CrossEye>,
    ring: FrameRing,
    accumulate: AccumulatePass,
    tonemap: TonemapPass,
    exposure: ExposurePass,
    /// The newest frame whose results were collected (`render_frame`, `wait_frame`).
    last_waited: Option<u64>,
}

impl Renderer {
    /// A one-view renderer with one frame slot (each `render_frame` waits for its frame).
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        space: Box<dyn SamplingSpace>,
        settings: RenderSettings,
    ) -> Result<Renderer> {
        let gpu_scene = GpuScene::upload(ctx, scene)?;
        Renderer::with_gpu_scene(ctx, gpu_scene, space, settings)
    }

    pub fn with_gpu_scene(
        ctx: &Arc<Context>,
        scene: GpuScene,
        space: Box<dyn SamplingSpace>,
        settings: RenderSettings,
    ) -> Result<Renderer> {
        Renderer::with_views(ctx, scene, vec![space], settings, 1)
    }

    /// A renderer of several views (`spaces`, one per eye) over one uploaded scene, keeping up
    /// to `frames_in_flight` frames on the GPU at once.
    pub fn with_views(
        ctx: &Arc<Context>,
        scene: GpuScene,
        spaces: Vec<Box<dyn SamplingSpace>>,
        settings: RenderSettings,
        frames_in_flight: usize,
    ) -> Result<Renderer> {
        if settings.max_depth == 0 {
            return Err(Error::Invalid(
                "max depth must be at least 1 (1 = emission seen directly)".into(),
            ));
        }
        let (lo, hi) = SURFACE_CELL_RANGE;
        if !(lo..=hi).contains(&settings.surface_cell) {
            return Err(Error::Invalid(format!(
                "surface noise cell {} must be in [{lo}, {hi}] footprints",
                settings.surface_cell
            )));
        }
        if spaces.is_empty() || spaces.len() > MAX_VIEWS {
            return Err(Error::Invalid(format!(
                "a renderer has 1 to {MAX_VIEWS} views, not {}",
                spaces.len()
            )));
        }
        if frames_in_flight == 0 {
            return Err(Error::Invalid("frames in flight must be at least 1".into()));
        }
        let views = build_views(ctx, spaces, &settings, frames_in_flight)?;
        let cross_eye = build_cross_eye(ctx, &views, &settings)?;
        let ring = FrameRing::new(ctx, frames_in_flight, max_passes(&views, &cross_eye))?;
        Ok(Renderer {
            accumulate: AccumulatePass::single(ctx)?,
            tonemap: TonemapPass::new(ctx)?,
            exposure: ExposurePass::new(ctx, frames_in_flight)?,
            ctx: ctx.clone(),
            scene,
            settings,
            views,
            cross_eye,
            ring,
            last_waited: None,
        })
    }

    /// Replaces every view (new spaces, a new denoiser or TAA, a resize) while frames are in
    /// flight: the old views are released once the frames that used them have completed.
    pub fn replace_views(
        &mut self,
        spaces: Vec<Box<dyn SamplingSpace>>,
        settings: RenderSettings,
    ) -> Result<()> {
        if spaces.is_empty() || spaces.len() > MAX_VIEWS {
            return Err(Error::Invalid(format!(
                "a renderer has 1 to {MAX_VIEWS} views, not {}",
                spaces.len()
            )));
        }
        let views = build_views(&self.ctx, spaces, &settings, self.ring.slots())?;
        let cross_eye = build_cross_eye(&self.ctx, &views, &settings)?;
        let passes = max_passes(&views, &cross_eye);
        if passes > max_passes(&self.views, &self.cross_eye) {
            // Timestamp pools are sized for the old views: a new ring, the old one drained.
            self.ring.finish()?;
            self.ring = FrameRing::new(&self.ctx, self.ring.slots(), passes)?;
            self.last_waited = None;
        }
        let old = std::mem::replace(&mut self.views, views);
        let old_cross_eye = std::mem::replace(&mut self.cross_eye, cross_eye);
        self.ring.defer_release(Box::new((old, old_cross_eye)));
        self.settings = settings;
        Ok(())
    }

    pub fn views(&self) -> &[View] {
        &self.views
    }

    /// Whether the eyes share their samples (`RenderSettings::cross_eye_reuse` on, or `auto`
    /// where they can).
    pub fn reuses_across_eyes(&self) -> bool {
        self.cross_eye.is_some()
    }

    pub fn view(&self, index: usize) -> &View {
        &self.views[index]
    }

    /// The first view's space (the only one of a mono renderer).
    pub fn space(&self) -> &dyn SamplingSpace {
        self.views[0].space.as_ref()
    }

    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }

    pub fn frames_in_flight(&self) -> usize {
        self.ring.slots()
    }

    /// The frame ring (slot waits, drains, deferred releases) for tests and the bench.
    pub fn ring(&self) -> &FrameRing {
        &self.ring
    }

    /// Keeps `resource` alive until every frame submitted so far has completed.
    pub fn defer_release(&mut self, resource: Box<dyn std::any::Any>) {
        self.ring.defer_release(resource);
    }

    /// Scales a material's emission at run time (`GpuScene::set_emission_scale`; `scene` is the
    /// scene this renderer was built from): a light switched off, dimmed or back on. The
    /// material table is host-visible and read by frames in flight, so this first waits for them:
    /// an edit, not a per-frame call.
    pub fn set_emission_scale(&mut self, scene: &Scene, material: usize, scale: f32) -> Result<()> {
        self.ring.finish()?;
        self.scene
            .set_emission_scale(&self.ctx, scene, material, scale)
    }

    /// The first view's denoiser and its state, when `settings.denoiser` names one.
    pub fn denoiser(&self) -> Option<&dyn Denoiser> {
        self.views[0].denoiser()
    }

    /// GPU time of each pass of the newest collected frame (every view's passes, tagged).
    pub fn timings(&self) -> &[PassTiming] {
        match self.last_waited.and_then(|f| self.ring.slot_of(f)) {
            Some(slot) => self.ring.recorder(slot).timings(),
            None => &[],
        }
    }

    /// GPU time of each pass of `frame`, once it has completed and while its slot holds it.
    pub fn frame_timings(&self, frame: u64) -> Result<&[PassTiming]> {
        Ok(self.ring.recorder(self.readable_slot(frame)?).timings())
    }

    /// The first view's sampling-grid TAA state, when `settings.taa` runs in the grid.
    pub fn taa(&self) -> Option<&Taa> {
        self.views[0].taa()
    }

    /// GPU bytes of TAA history carried between frames (first view; 0 when off).
    pub fn taa_history_bytes(&self) -> u64 {
        self.views[0].taa_history_bytes()
    }

    /// Writes `frame`'s uniforms into view `view`'s buffer of `slot`.
    fn write_frame_data(&self, view: usize, slot: usize, frame: &FrameUniforms) -> Result<()> {
        let FrameUniforms {
            camera,
            index: frame_index,
            max_depth,
            flags,
            jitter,
        } = *frame;
        let v = &self.views[view];
        let screen = v.space.screen_size().as_vec2();
        let prev = v.prev_camera.unwrap_or(camera);
        let seed = match self.settings.stereo_noise {
            StereoNoise::Independent => {
                self.settings.seed ^ (view as u32).wrapping_mul(0x9E37_79B9)
            }
            StereoNoise::Screen | StereoNoise::Surface => self.settings.seed,
        };
        let data = FrameData {
            world_from_view: camera.world_from_view,
            prev_view_from_world: prev.world_from_view.inverse(),
            fov_tan: camera.fov_tan,
            prev_fov_tan: prev.fov_tan,
            screen: Vec4::new(screen.x, screen.y, 1.0 / screen.x, 1.0 / screen.y),
            frame: UVec4::new(frame_index, seed, max_depth, flags),
            counts: UVec4::new(
                self.scene.light_count,
                self.scene.triangle_count,
                self.scene.material_count,
                self.scene.texture_count,
            ),
            scene_sphere: self.scene.bounding_sphere(),
            jitter: jitter.extend(0.0).extend(0.0),
            // Selection probability 0 tells the shaders not to sample it (BRDF-only).
            environment: match self.settings.environment_sampling {
                EnvironmentSampling::ImportanceMis => self.scene.environment_slots.0,
                EnvironmentSampling::BrdfOnly => {
                    self.scene.environment_slots.0 * Vec4::new(1.0, 1.0, 1.0, 0.0)
                }
            },
            environment_map: self.scene.environment_slots.1,
            path: Vec4::new(
                self.settings.path_regularisation,
                self.settings.surface_cell,
                if self.settings.resampling.mode == ResamplingMode::Off
                    || self.scene.triangle_light_count == 0
                {
                    0.0
                } else {
                    self.settings.resampling.brdf_candidates as f32
                },
                0.0,
            ),
            instancing: self.scene.instancing_slots,
        };
        v.slots[slot].frame_data.write(&[data])
    }

    /// Renders one real-time frame of every view and waits for it (the offline path: tests,
    /// `fovea render` with one slot). Returns the first view's counts.
    pub fn render_frame(&mut self, input: &FrameInput) -> Result<FrameStats> {
        let frame = self.submit(input, None)?;
        self.wait_frame(frame)?;
        self.frame_stats(frame, 0)
    }

    /// Frees the slot the next frame will use: waits for the frame in it (submitted
    /// `frames_in_flight` frames ago) and returns it. Its results stay readable until the next
    /// `submit`: a loop that writes every frame reads the returned frame here.
    pub fn retire_next(&mut self) -> Result<Option<u64>> {
        let retired = self.ring.retire_next()?;
        if retired.is_some() {
            self.last_waited = retired.max(self.last_waited);
        }
        Ok(retired)
    }

    /// Waits for `frame` (a drain when it is the newest).
    pub fn wait_frame(&mut self, frame: u64) -> Result<()> {
        self.ring.wait_for(frame)?;
        self.last_waited = Some(frame).max(self.last_waited);
        Ok(())
    }

    /// Waits for every frame in flight (before reading the last ones, or shutting down).
    pub fn finish(&mut self) -> Result<()> {
        self.ring.finish()?;
        if self.ring.next_frame() > 0 {
            self.last_waited = Some(self.ring.next_frame() - 1);
        }
        Ok(())
    }

    /// Records every view of one frame into one command buffer and submits it without waiting
    /// for it (only for the frame that used the same slot before, if still running). The last
    /// pass writes each view's own LDR image, or `target` when given. Returns the frame's id.
    pub fn submit(&mut self, input: &FrameInput, target: Option<&FrameTarget>) -> Result<u64> {
        let inputs = input.view_inputs();
        if inputs.len() != self.views.len() {
            return Err(Error::Invalid(format!(
                "the frame has {} views, the renderer {}",
                inputs.len(),
                self.views.len()
            )));
        }
        let retired = self.ring.retire_next()?;
        self.last_waited = retired.max(self.last_waited);
        let slot = self.ring.next_slot();
        for (v, view_input) in inputs.iter().enumerate() {
            self.prepare_view(v, slot, view_input, input)?;
        }
        let (_, rec) = self.ring.begin_next()?;
        if let Some(t) = target {
            rec.acquire_external(t.image);
        }
        let shared = FrameShared {
            scene: &self.scene,
            tonemap: &self.tonemap,
            accumulate: &self.accumulate,
            exposure: &self.exposure,
            settings: &self.settings,
            input,
        };
        // Every view's screen radiance first, then one exposure metered over all of them (both
        // eyes share it), then every view's display image.
        // A fixed array, not a Vec: the render loop makes no host allocation (tests/host_alloc.rs).
        let mut screens: [Option<_>; MAX_VIEWS] = std::array::from_fn(|_| None);
        // Every view's samples before any view's filters: cross-eye reuse reads both eyes'.
        for (v, (view, view_input)) in self.views.iter_mut().zip(inputs).enumerate() {
            rec.set_view(v as u32);
            record_samples(rec, view, slot, &shared, view_input)?;
        }
        if let (Some(cross_eye), [left, right]) = (&self.cross_eye, &self.views[..]) {
            let frames = [
                grid_frame!(left, &left.slots[slot], self.scene, inputs[0].camera),
                grid_frame!(right, &right.slots[slot], self.scene, inputs[1].camera),
            ];
            cross_eye.record(rec, [&frames[0], &frames[1]])?;
        }
        for (v, (view, view_input)) in self.views.iter_mut().zip(inputs).enumerate() {
            rec.set_view(v as u32);
            screens[v] = Some(record_filters(rec, view, slot, &shared, view_input)?);
        }
        if let Exposure::Auto(auto) = &self.settings.exposure {
            for (v, screen) in screens.iter().flatten().enumerate() {
                rec.set_view(v as u32);
                let metered = screen.screen.metered();
                self.exposure.record_meter(
                    rec,
                    auto,
                    metered,
                    screen.gaze,
                    screen.pixels_per_degree,
                )?;
            }
        }
        rec.set_view(0);
        self.exposure
            .record_adapt(rec, &self.settings.exposure, input.frame_seconds, slot)?;
        for (v, screen) in screens.into_iter().flatten().enumerate() {
            rec.set_view(v as u32);
            let external = target.map(|t| (t.image, t.offsets[v]));
            record_display(rec, screen, &shared, external)?;
        }
        let sync = match target {
            Some(t) => {
                rec.release_external(t.image, t.copy_to)?;
                t.sync
            }
            None => SubmitSync::default(),
        };
        rec.submit(sync)?;
        for (view, view_input) in self.views.iter_mut().zip(inputs) {
            view.prev_camera = Some(view_input.camera);
            view.prev_sampling = Some(view.space.params());
        }
        Ok(self.ring.submitted())
    }

    /// Host-side work of one view before recording: gaze, this slot's uniforms and table.
    fn prepare_view(
        &mut self,
        v: usize,
        slot: usize,
        view_input: &ViewInput,
        input: &FrameInput,
    ) -> Result<()> {
        let cull = self.settings.offscreen_samples == OffscreenSamples::Cull;
        if let Some(gaze) = view_input.gaze {
            self.views[v].space.set_gaze(gaze)?;
        }
        let jitter = self
            .settings
            .taa
            .settings()
            .map(|t| t.jitter(input.frame_index));
        let flags = if jitter.is_some() {
            FRAME_FLAG_HALTON_JITTER
        } else {
            0
        } | if self.scene.alpha_masked {
            FRAME_FLAG_ALPHA_MASK
        } else {
            0
        } | if self.settings.texture_lod == TextureLod::RayCones {
            FRAME_FLAG_TEXTURE_LOD
        } else {
            0
        } | if self.settings.offscreen_samples == OffscreenSamples::Cull {
            FRAME_FLAG_CULL_OFFSCREEN
        } else {
            0
        } | if self.settings.stereo_noise == StereoNoise::Surface {
            FRAME_FLAG_SURFACE_NOISE
        } else {
            0
        };
        let uniforms = FrameUniforms {
            camera: view_input.camera,
            index: input.frame_index,
            max_depth: self.settings.max_depth,
            flags,
            jitter: jitter.unwrap_or(Vec2::ZERO),
        };
        self.write_frame_data(v, slot, &uniforms)?;
        let view = &mut self.views[v];
        view.ensure_readbacks(&self.ctx, slot, input.read_hdr, input.read_grid)?;
        let s = &view.slots[slot];
        s.sampling.write(&[view.space.params()])?;
        view.space.write_sampling_table(&mut view.table_rows);
        let n = view.table_rows.len();
        // Without a previous frame its half repeats this frame's (no pass reads it then).
        match view.prev_sampling {
            Some(_) if view.prev_table_rows.len() == n => {
                view.table_rows.extend_from_slice(&view.prev_table_rows)
            }
            _ => view.table_rows.extend_from_within(..n),
        }
        s.sampling_table.write(&view.table_rows)?;
        view.prev_table_rows.clear();
        view.prev_table_rows
            .extend_from_slice(&view.table_rows[..n]);
        view.write_trace_tiles(slot, cull)
    }

    fn readable_slot(&self, frame: u64) -> Result<usize> {
        match self.ring.slot_of(frame) {
            Some(slot) if self.ring.is_readable(frame) => Ok(slot),
            Some(_) => Err(Error::Invalid(format!(
                "frame {frame} is still in flight (wait for it first)"
            ))),
            None => Err(Error::Invalid(format!(
                "frame {frame} is not held: its slot holds a later frame"
            ))),
        }
    }

    fn last_slot(&self) -> Result<usize> {
        let frame = self
            .last_waited
            .ok_or_else(|| Error::Invalid("no frame has completed yet".into()))?;
        self.readable_slot(frame)
    }

    /// The exposure multiplier a completed frame was displayed with (every view shares it).
    pub fn frame_exposure(&self, frame: u64) -> Result<f32> {
        self.exposure.read_slot(self.readable_slot(frame)?)
    }

    /// Exact counts of one view of a completed frame (from the GPU's own counters).
    pub fn frame_stats(&self, frame: u64, view: usize) -> Result<FrameStats> {
        self.views[view].slots[self.readable_slot(frame)?].stats()
    }

    /// Tonemapped pixels of one view of a completed frame, RGBA8, rows top to bottom.
    pub fn read_view_ldr(&self, frame: u64, view: usize, out: &mut Vec<u8>) -> Result<()> {
        let b = &self.views[view].slots[self.readable_slot(frame)?].ldr_readback;
        out.resize(b.size as usize, 0);
        b.read_into(out)
    }

    /// Linear screen image of one view of a completed frame (`FrameInput::read_hdr`), RGBA32F.
    pub fn read_view_hdr(&self, frame: u64, view: usize, out: &mut Vec<[f32; 4]>) -> Result<()> {
        read_optional(
            &self.views[view].slots[self.readable_slot(frame)?].hdr_readback,
            "read_hdr",
            out,
        )
    }

    /// Tonemapped sampling-grid image of one view of a completed frame (`read_grid`), RGBA8.
    pub fn read_view_grid_ldr(&self, frame: u64, view: usize, out: &mut Vec<u8>) -> Result<()> {
        read_optional(
            &self.views[view].slots[self.readable_slot(frame)?].grid_readback,
            "read_grid",
            out,
        )
    }

    /// The newest collected frame's tonemapped pixels (first view), RGBA8, rows top to bottom.
    pub fn read_ldr(&self, out: &mut Vec<u8>) -> Result<()> {
        let b = &self.views[0].slots[self.last_slot()?].ldr_readback;
        out.resize(b.size as usize, 0);
        b.read_into(out)
    }

    /// The newest collected frame's tonemapped sampling-grid image (first view), RGBA8.
    pub fn read_grid_ldr(&self, out: &mut Vec<u8>) -> Result<()> {
        read_optional(
            &self.views[0].slots[self.last_slot()?].grid_readback,
            "read_grid",
            out,
        )
    }

    /// The newest collected frame's (or reference's) linear screen image (first view), RGBA32F.
    pub fn read_hdr(&self, out: &mut Vec<[f32; 4]>) -> Result<()> {
        read_optional(
            &self.views[0].slots[self.last_slot()?].hdr_readback,
            "read_hdr",
            out,
        )
    }

    /// Converged linear radiance of the first view: the mean of `spp` samples per pixel with
    /// paths of up to `max_depth` vertices. `progress` gets the number of samples done after
    /// each submission.
    pub fn render_reference(
        &mut self,
        camera: &CameraPose,
        spp: u32,
        max_depth: u32,
        progress: impl FnMut(u32),
    ) -> Result<Vec<[f32; 4]>> {
        self.render_reference_samples(camera, 0..spp, max_depth, progress)
    }

    /// As [`Renderer::render_reference`], the mean of the samples whose indices lie in `samples`:
    /// a sample index draws the same paths in every call, so references of disjoint ranges are
    /// parts of the reference of their union (split across processes and summed).
    pub fn render_reference_samples(
        &mut self,
        camera: &CameraPose,
        samples: std::ops::Range<u32>,
        max_depth: u32,
        mut progress: impl FnMut(u32),
    ) -> Result<Vec<[f32; 4]>> {
        let (first, spp) = (samples.start, samples.len() as u32);
        if spp == 0 || max_depth == 0 {
            return Err(Error::Invalid(
                "reference needs spp ≥ 1 and max depth ≥ 1".into(),
            ));
        }
        if self.space().grid_size() != self.space().screen_size() {
            return Err(Error::Invalid(
                "references are rendered in Cartesian space".into(),
            ));
        }
        self.finish()?;
        let screen = self.space().screen_size();
        {
            let view = &mut self.views[0];
            // The G-buffer is overwritten and the previous camera forgotten: no history survives.
            view.prev_camera = None;
            view.prev_sampling = None;
            if view.accum.is_none() {
                view.accum = Some(Image::new(
                    &self.ctx,
                    "accum",
                    screen.x,
                    screen.y,
                    vk::Format::R32G32B32A32_SFLOAT,
                )?);
            }
        }
        let mut done = 0;
        while done < spp {
            let batch = (spp - done).min(REFERENCE_SAMPLES_PER_SUBMIT);
            let slot = self.ring.next_slot();
            self.views[0].ensure_readbacks(&self.ctx, slot, true, false)?;
            let alpha = if self.scene.alpha_masked {
                FRAME_FLAG_ALPHA_MASK
            } else {
                0
            };
            let uniforms = FrameUniforms {
                camera: *camera,
                index: 0,
                max_depth,
                flags: FRAME_FLAG_REFERENCE | alpha,
                jitter: Vec2::ZERO,
            };
            self.write_frame_data(0, slot, &uniforms)?;
            self.views[0].slots[slot]
                .sampling
                .write(&[self.views[0].space.params()])?;
            self.views[0].write_trace_tiles(slot, false)?;
            let (_, rec) = self.ring.begin_next()?;
            let view = &self.views[0];
            let (s, accum) = (&view.slots[slot], view.accum.as_ref().expect("made above"));
            let frame = GridFrame {
                gbuffer: &view.gbuffer,
                frame_data: &s.frame_data,
                sampling: &s.sampling,
                current: view.space.params(),
                previous: None,
                sampling_table: &s.sampling_table,
                tiles: TileList::new(&s.trace_tiles, &view.tiles),
                camera_origin: camera.world_from_view.w_axis.truncate(),
                materials: &self.scene.materials,
            };
            for i in done..done + batch {
                // The sample index seeds the paths; `i` counts the samples in the mean so far.
                view.trace
                    .record(rec, &frame, &self.scene, &s.ray_counters, first + i, None)?;
                self.accumulate.record(rec, &view.gbuffer.color, accum, i)?;
            }
            if done + batch == spp {
                rec.copy_image_to_buffer(
                    "readback_hdr",
                    accum,
                    s.hdr_readback.as_ref().expect("made above"),
                )?;
            }
            rec.submit(SubmitSync::default())?;
            let frame = self.ring.submitted();
            // One batch at a time: the accumulation image carries the sum between batches
            // (ordered on the GPU anyway), and waiting keeps the progress bar honest.
            self.wait_frame(frame)?;
            done += batch;
            progress(done);
        }
        let mut out = Vec::new();
        self.read_hdr(&mut out)?;
        Ok(out)
    }
}

impl Drop for Renderer {
    fn drop(&mut self) {
        // Views and the scene go before the ring: nothing in flight may still use them.
        let _ = self.ring.finish();
    }
}

fn build_views(
    ctx: &Arc<Context>,
    spaces: Vec<Box<dyn SamplingSpace>>,
    settings: &RenderSettings,
    slots: usize,
) -> Result<Vec<View>> {
    spaces
        .into_iter()
        .map(|space| View::new(ctx, space, settings, slots))
        .collect()
}

/// Cross-eye reuse when the settings ask for it (`auto`: where the eyes can share) and there are
/// two views (the eyes).
fn build_cross_eye(
    ctx: &Arc<Context>,
    views: &[View],
    settings: &RenderSettings,
) -> Result<Option<CrossEye>> {
    let [left, right] = views else {
        return Ok(None);
    };
    let spaces = [left.space.as_ref(), right.space.as_ref()];
    let build = match settings.cross_eye_reuse {
        CrossEyeReuse::Off => false,
        CrossEyeReuse::On => true,
        CrossEyeReuse::Auto => CrossEye::refusal(spaces).is_none(),
    };
    build.then(|| CrossEye::new(ctx, spaces)).transpose()
}

/// Timestamped passes one frame may hold: every view's passes, or a reference submission.
fn max_passes(views: &[View], cross_eye: &Option<CrossEye>) -> u32 {
    // Each view's passes and its exposure meter, the frame's one exposure adaptation, and the
    // cross-eye passes between the views' samples and their filters.
    let frame: u32 = views.iter().map(|v| v.max_passes() + 1).sum::<u32>()
        + 1
        + cross_eye.as_ref().map_or(0, |_| CrossEye::PASSES);
    // A reference batch: trace and accumulate per sample, the idle tiles' clear, the copy.
    frame.max(2 * REFERENCE_SAMPLES_PER_SUBMIT + 2) + 2
}

fn read_optional<T: bytemuck::Pod>(
    buffer: &Option<Buffer>,
    flag: &str,
    out: &mut Vec<T>,
) -> Result<()> {
    let b = buffer.as_ref().ok_or_else(|| {
        Error::Invalid(format!(
            "no frame asked for this read-back (FrameInput::{flag})"
        ))
    })?;
    out.resize(b.size as usize / std::mem::size_of::<T>(), T::zeroed());
    b.read_into(out)
}

/// What every view of one frame records with: the scene, the shared passes and settings, and
/// the frame's input.
struct FrameShared<'a> {
    scene: &'a GpuScene,
    tonemap: &'a TonemapPass,
    accumulate: &'a AccumulatePass,
    exposure: &'a ExposurePass,
    settings: &'a RenderSettings,
    input: &'a FrameInput,
}

/// One view's frame up to its screen radiance, and where its display image and read-backs go.
struct ViewScreen<'a> {
    screen: ScreenOut<'a>,
    /// The sampling grid's radiance (the grid debug view tone-maps it).
    grid_hdr: &'a Image,
    view: ViewTargets<'a>,
    /// The gaze (pixels) and the pixels per degree at the view's centre, for the exposure meter.
    gaze: Vec2,
    pixels_per_degree: f32,
}

/// A view's own display images and this slot's read-back buffers.
struct ViewTargets<'a> {
    ldr: &'a Image,
    grid_ldr: &'a Image,
    ldr_readback: &'a Buffer,
    hdr_readback: Option<&'a Buffer>,
    grid_readback: Option<&'a Buffer>,
}

/// Pixels per degree at the centre of a view `width` pixels wide through `camera`'s frustum.
fn pixels_per_degree(camera: &CameraPose, width: u32) -> f32 {
    let span = camera.fov_tan.y.atan() - camera.fov_tan.x.atan();
    width as f32 / span.to_degrees().max(1e-3)
}

/// Records one view's samples of a frame: trace → resampling (→ each texel's mean where a space
/// traces several), into the view's G-buffer.
fn record_samples(
    rec: &mut FrameRecorder,
    view: &mut View,
    slot: usize,
    shared: &FrameShared,
    view_input: &ViewInput,
) -> Result<()> {
    let FrameShared {
        scene, accumulate, ..
    } = *shared;
    let s = &view.slots[slot];
    rec.fill_buffer("clear_counters", &s.ray_counters, 0)?;
    // Denoisers work in the sampling grid (Cartesian samples are the screen).
    let frame = grid_frame!(view, s, scene, view_input.camera);
    if let Some(d) = &mut view.denoiser {
        d.record_before_trace(rec, &frame)?;
    }
    let gradients = view.denoiser.as_ref().and_then(|d| d.gradient_targets());
    let trace = view
        .trace_gradients
        .as_ref()
        .or(view.trace_resampled.as_ref())
        .unwrap_or(&view.trace);
    trace.record(rec, &frame, scene, &s.ray_counters, 0, gradients)?;
    // The primary hits' direct light, from reservoirs reused over frames and grid neighbours.
    if let Some(resampling) = &mut view.resampling {
        resampling.record(rec, &frame, scene, &s.ray_counters)?;
    }
    // Spaces tracing several samples in some texels: sample k where k < the texel's count, each
    // texel's mean kept (no denoiser or TAA runs on them).
    if let Some(mean) = &view.sample_mean {
        accumulate.record_traced(rec, &view.gbuffer.color, mean, 0)?;
        for k in 1..view.space.samples_per_texel() {
            trace.record(rec, &frame, scene, &s.ray_counters, k, None)?;
            accumulate.record_traced(rec, &view.gbuffer.color, mean, k)?;
        }
    }
    Ok(())
}

/// Records one view's frame from its samples to its screen radiance: denoiser → TAA → the way
/// back to the screen (a pending foveated blur left to `record_display`).
fn record_filters<'a>(
    rec: &mut FrameRecorder,
    view: &'a mut View,
    slot: usize,
    shared: &FrameShared<'a>,
    view_input: &ViewInput,
) -> Result<ViewScreen<'a>> {
    let FrameShared {
        scene,
        settings,
        input,
        ..
    } = *shared;
    let jitter = settings.taa.settings().map(|t| t.jitter(input.frame_index));
    let s = &view.slots[slot];
    let frame = grid_frame!(view, s, scene, view_input.camera);
    let traced = view.sample_mean.as_ref().unwrap_or(&view.gbuffer.color);
    let denoised = match &mut view.denoiser {
        Some(d) => d.record(rec, &frame)?,
        None => traced,
    };
    let grid_hdr = match (&mut view.taa, jitter) {
        (Some(taa), Some(jitter)) => taa.record(rec, denoised, &frame, jitter)?,
        _ => denoised,
    };
    let screen = view.back.record(
        rec,
        &WayBackFrame {
            space: view.space.as_ref(),
            grid: frame,
            radiance: grid_hdr,
            blur: &settings.blur,
            jitter,
        },
    )?;
    Ok(ViewScreen {
        screen,
        grid_hdr,
        view: ViewTargets {
            ldr: &view.ldr,
            grid_ldr: &view.grid_ldr,
            ldr_readback: &s.ldr_readback,
            hdr_readback: s.hdr_readback.as_ref(),
            grid_readback: s.grid_readback.as_ref(),
        },
        gaze: view.space.gaze(),
        pixels_per_degree: pixels_per_degree(&view_input.camera, view.space.screen_size().x),
    })
}

/// Records one view's display image with the frame's exposure: the tonemap (or the pending
/// blur's last axis) into the view's own LDR image (read back into the slot) or into `external`
/// at its offset.
fn record_display(
    rec: &mut FrameRecorder,
    screen: ViewScreen,
    shared: &FrameShared,
    external: Option<(&ExternalImage, UVec2)>,
) -> Result<()> {
    let ViewScreen {
        screen,
        grid_hdr,
        view,
        ..
    } = screen;
    let display = ToneTarget {
        ldr: match external {
            Some((image, offset)) => LdrTarget::External { image, offset },
            None => LdrTarget::Own(view.ldr),
        },
        exposure: shared.exposure.state(),
        curve: shared.settings.tone_curve,
    };
    match (screen, shared.input.read_hdr) {
        // Unless the frame's radiance is read back, the blur writes the display image itself
        // (one full-screen pass fewer).
        (ScreenOut::Unblurred(pending), false) => pending.display(rec, display)?,
        (screen, read_hdr) => {
            let screen_hdr = screen.into_radiance(rec)?;
            shared
                .tonemap
                .record(rec, "tonemap", screen_hdr, &display)?;
            if let (true, Some(b)) = (read_hdr, view.hdr_readback) {
                rec.copy_image_to_buffer("readback_hdr", screen_hdr, b)?;
            }
        }
    }
    if external.is_none() {
        rec.copy_image_to_buffer("readback", view.ldr, view.ldr_readback)?;
    }
    if let (true, Some(b)) = (shared.input.read_grid, view.grid_readback) {
        let grid_target = ToneTarget {
            ldr: LdrTarget::Own(view.grid_ldr),
            ..display
        };
        shared
            .tonemap
            .record(rec, "tonemap_grid", grid_hdr, &grid_target)?;
        rec.copy_image_to_buffer("readback_grid", view.grid_ldr, b)?;
    }
    Ok(())
}
