//! Sampling spaces: where the tracer's samples lie on the screen. Each space describes its grid,
//! gives CPU forward/inverse mappings (tests and tools) and names the trace-kernel variant whose
//! GLSL include (`shaders/sampling/`) implements the same mapping on the GPU.

mod acuity;
mod cartesian;
mod composite;
mod fixed_foveation;
mod linear_falloff;
mod log_polar;
mod pixel_blocks;
pub mod random;
mod random_acuity;
#[cfg(test)]
mod test_draws;
mod trace_tiles;
mod uniform_budget;
mod visual_polar;
mod visual_polar_clipped;
mod visual_polar_headset;
mod visual_polar_screen_axis;
mod visual_polar_space;
mod vrs_tiles;

pub use cartesian::Cartesian;
pub use composite::{CompositeMode, CompositeParams};
pub use fixed_foveation::FixedFoveation;
pub use linear_falloff::{FalloffShape, LinearFalloff, FALLOFF_BUDGET_OF_VP};
pub use log_polar::{exp_f32, pow_unit, LogPolarExtent, LogPolarLaw, LogPolarParams};
pub use pixel_blocks::{BlockShape, PixelBlocks, BLOCK_LEVELS};
pub use random_acuity::RandomAcuity;
pub use trace_tiles::{tile_count, TraceTiles, TRACE_TILE};
pub use uniform_budget::UniformBudget;
pub use visual_polar::{
    params_need_general_kernel, params_select_clipped_layout, Eccentricity, InverseCdf, RadialLaw,
    RadiusMode, VisualPolar, VisualPolarParams, VpLayout,
};
pub use visual_polar_clipped::{on_screen_arcs, ColumnArcs};
pub use visual_polar_headset::{FovTangents, HeadsetAxis};
pub use visual_polar_screen_axis::{ScreenAxis, AXIS_KNOT_TEXELS, AXIS_PIECES};
pub use vrs_tiles::{VrsTiles, VRS_TILE};

use crate::error::Result;
use crate::layouts::SamplingParams;
use glam::{UVec2, Vec2};

/// Whether `p` lies in the rectangle [0, size) (texel or pixel units).
fn within(p: Vec2, size: UVec2) -> bool {
    p.cmpge(Vec2::ZERO).all() && p.cmplt(size.as_vec2()).all()
}

/// How a space's samples come back to the screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WayBack {
    /// The grid is the screen.
    Direct,
    /// A polar grid: φ-mips, the remap and the foveated blur (`blur_axis`).
    Remap,
    /// A regular grid coarser than the screen: bilinear upscaling.
    Upscale,
    /// The screen's pixels, some not traced (alpha 0): push-pull hole filling, then the foveated
    /// blur (`blur_axis`).
    Fill,
    /// Samples anywhere on the screen: each splatted to its pixel (`passes/splat`), then as
    /// `Fill`.
    Splat,
    /// An atlas of pixel blocks: each pixel interpolated between its level's block centres
    /// (`passes/block_fill`), no blur.
    BlockFill,
}

/// What the pipeline may do with a space: asked by the renderer instead of testing concrete types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpaceCapabilities {
    pub way_back: WayBack,
    /// The denoisers and TAA can reproject and filter in this grid (their kernels address it).
    pub temporal_filters: bool,
    /// Why they cannot, for the error (when `temporal_filters` is false).
    pub filters_note: &'static str,
}

pub trait SamplingSpace {
    /// Name used in reports and on the command line (`--method`).
    fn name(&self) -> &'static str;
    /// Variant suffix of the kernels compiled for this space (e.g. `passes/trace.cartesian`).
    fn shader_variant(&self) -> &'static str;
    /// Variant of the trace kernel: `shader_variant` unless the space compiles a layout-specific
    /// mapping (lavapipe pays for both sides of a branch, so the paper's VP layout gets a trace
    /// kernel without the screen-clipped path).
    fn trace_variant(&self) -> &'static str {
        self.shader_variant()
    }
    /// Size of the sampling grid in texels (the size of every per-sample image).
    fn grid_size(&self) -> UVec2;
    fn screen_size(&self) -> UVec2;
    /// Texels that hold a sample (clipped texels are not traced).
    fn sample_count(&self) -> u64;
    /// The GPU parameters of this space (binding `sampling`).
    fn params(&self) -> SamplingParams;
    /// A per-frame table the space's kernel variant reads (RGBA32F texels, binding
    /// `sampling_table`; Visual-Polar: the per-column on-screen arcs). Empty when the space needs
    /// none; its length never changes for one space.
    fn sampling_table(&self) -> Vec<[f32; 4]> {
        let mut table = Vec::new();
        self.write_sampling_table(&mut table);
        table
    }
    /// `sampling_table` into a caller-owned vector (cleared first), so the render loop reuses
    /// its capacity instead of allocating every frame.
    fn write_sampling_table(&self, out: &mut Vec<[f32; 4]>) {
        out.clear();
    }
    /// Screen position (pixels, y down) of a grid position (texel units, texel centre = +0.5).
    fn grid_to_screen(&self, grid: Vec2) -> Option<Vec2>;
    /// Grid position of a screen position; `None` where the space has no sample.
    fn screen_to_grid(&self, screen: Vec2) -> Option<Vec2>;
    /// Current gaze point (screen pixels).
    fn gaze(&self) -> Vec2;
    /// Re-centres the space on a new gaze point (screen pixels); the grid size never changes, so
    /// per-sample images stay valid. Spaces that ignore the gaze only record it.
    fn set_gaze(&mut self, gaze: Vec2) -> Result<()>;
    /// The Visual-Polar space, when this grid is one (the grid blur and the filters address it
    /// through its parameters).
    fn visual_polar(&self) -> Option<&VisualPolar> {
        None
    }
    /// The eccentricity axis that shapes the foveated blur of the way back (the polar spaces:
    /// their own; the sparse spaces: the density they follow); `None`: no foveated blur.
    fn blur_axis(&self) -> Option<&VisualPolar> {
        None
    }
    /// The most samples one texel traces per frame (the trace runs this many times, sample index
    /// k tracing where k < the texel's count, and the results are averaged per texel).
    fn samples_per_texel(&self) -> u32 {
        1
    }
    /// This frame's trace tiles (`trace_tiles.rs`): the live ones run the tracer, the idle ones
    /// hold no sample it would trace (`cull`: samples far off the screen are culled) and are only
    /// cleared. Default: every tile live.
    fn trace_tiles(&self, cull: bool, tiles: &mut TraceTiles) {
        let _ = cull;
        tiles.fill_live(self.grid_size());
    }
    /// The space's capabilities (default: a screen-sized grid every filter supports).
    fn capabilities(&self) -> SpaceCapabilities {
        SpaceCapabilities {
            way_back: WayBack::Direct,
            temporal_filters: true,
            filters_note: "",
        }
    }
}
