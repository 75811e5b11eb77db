//! Cross-eye reuse (`RenderSettings::cross_eye_reuse`; docs/design/binocular.md): in a stereo
//! frame, after both eyes have traced (and resampled), each eye's samples take the other eye's
//! sample of the same surface into their demodulated radiance, so both eyes' filters start from
//! up to twice the samples and from one shared estimate where the surface looks the same from
//! both eyes. Two kernels: `cross_eye` merges into a scratch image per eye (each eye reads the
//! other's samples as traced), `cross_eye_resolve` writes the merged radiance back into the eye's
//! G-buffer (colour = radiance × this eye's albedo) once both merges have run.

use crate::error::{Error, Result};
use crate::graph::{read_buffer, read_image, read_texels, write_image, FrameRecorder};
use crate::layouts::CrossEyePush;
use crate::passes::grid::GridFrame;
use crate::passes::{Kernel, Pass};
use crate::sampling::SamplingSpace;
use crate::vk::{Context, Image};
use ash::vk;
use glam::UVec4;
use std::sync::Arc;

struct Merge;

impl Kernel for Merge {
    const SHADER: &'static str = "passes/cross_eye";
    type Push = CrossEyePush;
}

struct Resolve;

impl Kernel for Resolve {
    const SHADER: &'static str = "passes/cross_eye_resolve";
    type Push = ();
}

/// The two passes and each eye's merged radiance.
pub struct CrossEye {
    merge: Pass<Merge>,
    resolve: Pass<Resolve>,
    merged: [Image; 2],
}

impl CrossEye {
    /// Timestamped passes per frame: a merge and a resolve per eye.
    pub const PASSES: u32 = 4;

    /// Why the eyes of `spaces` cannot share their samples, if they cannot: a
    /// space whose grid the filters do not address (no per-sample G-buffer to find the other
    /// eye's sample in), or two eyes of different spaces or sizes. A-SVGF shares too: its
    /// gradients compare the tracer's own estimates (the visibility image), which the merge leaves
    /// alone.
    pub fn refusal([left, right]: [&dyn SamplingSpace; 2]) -> Option<String> {
        let caps = left.capabilities();
        if !caps.temporal_filters {
            return Some(format!(
                "cross-eye reuse: the {} space cannot match its samples between the eyes {}",
                left.name(),
                caps.filters_note
            ));
        }
        let shape = |s: &dyn SamplingSpace| (s.shader_variant(), s.grid_size(), s.screen_size());
        if shape(left) != shape(right) {
            return Some(format!(
                "cross-eye reuse: the eyes' spaces differ ({} {:?} against {} {:?}); both eyes \
                 need one space at one size",
                left.name(),
                shape(left),
                right.name(),
                shape(right)
            ));
        }
        None
    }

    /// The passes for the eyes' spaces; an error with the [`refusal`](Self::refusal) where they
    /// cannot share.
    pub fn new(ctx: &Arc<Context>, spaces: [&dyn SamplingSpace; 2]) -> Result<CrossEye> {
        if let Some(reason) = Self::refusal(spaces) {
            return Err(Error::Invalid(reason));
        }
        let space = spaces[0];
        let grid = space.grid_size();
        let image = |name| Image::new(ctx, name, grid.x, grid.y, vk::Format::R32G32B32A32_SFLOAT);
        Ok(CrossEye {
            merge: Pass::new(ctx, space.shader_variant())?,
            resolve: Pass::single(ctx)?,
            merged: [
                image("cross_eye.merged_left")?,
                image("cross_eye.merged_right")?,
            ],
        })
    }

    /// Merges the two eyes' samples of this frame into both eyes' G-buffers (`eyes[0]` the
    /// first view's frame, `eyes[1]` the second's).
    pub fn record(&self, rec: &mut FrameRecorder, eyes: [&GridFrame; 2]) -> Result<()> {
        for (e, merged) in self.merged.iter().enumerate() {
            let (mine, theirs) = (eyes[e], eyes[1 - e]);
            let (g, o) = (mine.gbuffer, theirs.gbuffer);
            let binds = [
                read_buffer("frame", mine.frame_data),
                read_buffer("other_frame", theirs.frame_data),
                read_image("radiance", &g.radiance),
                read_image("normal_depth", &g.normal_depth),
                read_image("position", &g.position),
                read_image("ids", &g.ids),
                read_image("other_radiance", &o.radiance),
                read_image("other_normal_depth", &o.normal_depth),
                read_image("other_position", &o.position),
                read_image("other_ids", &o.ids),
                write_image("merged", merged),
                // The other eye's grid addressing (the screen-clipped layout's arcs).
                read_texels("grid_columns", theirs.sampling_table),
            ];
            let push = CrossEyePush {
                other: theirs.current,
                config: UVec4::ZERO,
            };
            let size = g.size;
            rec.set_view(e as u32);
            self.merge
                .dispatch(rec, "cross_eye", &binds, &push, [size.x, size.y, 1])?;
        }
        for (e, (eye, merged)) in eyes.iter().zip(&self.merged).enumerate() {
            rec.set_view(e as u32);
            let g = eye.gbuffer;
            let binds = [
                read_image("merged", merged),
                read_image("albedo", &g.albedo),
                write_image("color", &g.color),
                write_image("radiance", &g.radiance),
            ];
            let size = g.size;
            self.resolve
                .dispatch(rec, "cross_eye_resolve", &binds, &(), [size.x, size.y, 1])?;
        }
        Ok(())
    }
}
