//! Clears the trace's idle tiles (`SamplingSpace::trace_tiles`) to what the tracer writes for a
//! sample it does not trace, and counts their culled samples: the trace dispatches only the live
//! tiles, because lavapipe runs masked-off lanes at nearly the cost of live ones.

use super::push_bytes;
use crate::error::Result;
use crate::graph::{read_buffer, write_buffer, write_image, FrameRecorder};
use crate::layouts::TraceClearPush;
use crate::passes::grid::{GBuffer, TileList};
use crate::vk::{Buffer, ComputePipeline, Context};
use glam::UVec4;
use std::sync::Arc;

pub struct TraceClearPass {
    plain: Arc<ComputePipeline>,
    /// Also clears A-SVGF's visibility image.
    gradients: Arc<ComputePipeline>,
}

impl TraceClearPass {
    pub fn new(ctx: &Arc<Context>) -> Result<TraceClearPass> {
        let size = std::mem::size_of::<TraceClearPush>() as u32;
        Ok(TraceClearPass {
            plain: ComputePipeline::shared(ctx, "passes/trace_clear.plain", size)?,
            gradients: ComputePipeline::shared(ctx, "passes/trace_clear.gradients", size)?,
        })
    }

    /// The idle tiles of `tiles` in `out` (nothing to record when there are none).
    pub fn record(
        &self,
        rec: &mut FrameRecorder,
        tiles: &TileList,
        ray_counters: &Buffer,
        out: &GBuffer,
    ) -> Result<()> {
        if tiles.idle == 0 {
            return Ok(());
        }
        let push = TraceClearPush {
            config: UVec4::new(tiles.live, tiles.culled_samples, 0, 0),
        };
        // A fixed array (no host allocation per frame): the plain kernel binds all but the last.
        let g = out.write_binds();
        let binds = [
            g[0],
            g[1],
            g[2],
            g[3],
            g[4],
            g[5],
            g[6],
            read_buffer("tiles", tiles.buffer),
            write_buffer("ray_counters", ray_counters),
            write_image(
                "out_visibility",
                out.visibility.as_ref().unwrap_or(&out.color),
            ),
        ];
        let (pipeline, binds) = match out.visibility {
            Some(_) => (&self.gradients, &binds[..]),
            None => (&self.plain, &binds[..binds.len() - 1]),
        };
        rec.dispatch(
            "trace_clear",
            pipeline,
            binds,
            push_bytes(&push),
            tiles.idle_threads(),
        )
    }
}
