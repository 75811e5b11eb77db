//! Helpers for the denoiser tests (SVGF/TAA, BMFR, screen-space TAA): uploads of synthetic
//! G-buffer data, masks and metrics.

use ash::vk;
use fovea_renderer::frame::{CameraPose, FrameInput, RenderSettings};
use fovea_renderer::graph::FrameRecorder;
use fovea_renderer::passes::denoise::DenoiserSettings;
use fovea_renderer::passes::grid::GridFrame;
use fovea_renderer::passes::grid::{GBuffer, OwnedTileList};
use fovea_renderer::pipeline::Renderer;
use fovea_renderer::sampling::{SamplingSpace, VisualPolar, VisualPolarParams};
use fovea_renderer::vk::{Buffer, Context, Image};
use glam::{UVec2, Vec2};
use std::sync::Arc;

/// Any plain-old-data texels into an image of the matching format.
pub fn upload<T: bytemuck::Pod>(ctx: &Arc<Context>, image: &Image, texels: &[T]) {
    assert_eq!(texels.len(), image.width as usize * image.height as usize);
    let buffer = Buffer::with_data(
        ctx,
        "test_upload",
        texels,
        vk::BufferUsageFlags::TRANSFER_SRC,
    )
    .unwrap();
    let mut rec = FrameRecorder::new(ctx, 2).unwrap();
    rec.begin().unwrap();
    rec.copy_buffer_to_image("test_upload", &buffer, image)
        .unwrap();
    rec.submit_and_wait().unwrap();
}

/// One texel of a synthetic G-buffer.
#[derive(Clone, Copy, Debug)]
pub struct Texel {
    pub radiance: [f32; 3],
    /// Shading normal (need not be unit length: BMFR uses it as a feature).
    pub normal: [f32; 3],
    /// Camera-relative position; its depth is −z.
    pub position: [f32; 3],
    pub mesh: u32,
    /// Previous screen position (−1: none).
    pub motion: Vec2,
}

const HALF_ONE: u16 = 0x3c00;

/// Fills the G-buffer like the tracer would (albedo 1): `None` = a texel without a sample.
pub fn upload_gbuffer(ctx: &Arc<Context>, g: &GBuffer, texels: &[Option<Texel>]) {
    let colour: Vec<[f32; 4]> = texels
        .iter()
        .map(|t| {
            t.map_or([0.0; 4], |t| {
                [t.radiance[0], t.radiance[1], t.radiance[2], 1.0]
            })
        })
        .collect();
    upload(ctx, &g.color, &colour);
    upload(ctx, &g.radiance, &colour);
    upload(
        ctx,
        &g.albedo,
        &texels
            .iter()
            .map(|t| {
                if t.is_some() {
                    [HALF_ONE; 4]
                } else {
                    [0u16; 4]
                }
            })
            .collect::<Vec<_>>(),
    );
    let nd: Vec<[f32; 4]> = texels
        .iter()
        .map(|t| {
            t.map_or([0.0; 4], |t| {
                [t.normal[0], t.normal[1], t.normal[2], -t.position[2]]
            })
        })
        .collect();
    upload(ctx, &g.normal_depth, &nd);
    // w: depth gradient per texel, 0.2 % of the depth.
    let pos: Vec<[f32; 4]> = texels
        .iter()
        .map(|t| {
            t.map_or([0.0; 4], |t| {
                [
                    t.position[0],
                    t.position[1],
                    t.position[2],
                    -0.002 * t.position[2],
                ]
            })
        })
        .collect();
    upload(ctx, &g.position, &pos);
    upload(
        ctx,
        &g.ids,
        &texels
            .iter()
            .map(|t| t.map_or([0u32; 2], |t| [1, t.mesh << 16]))
            .collect::<Vec<_>>(),
    );
    upload(
        ctx,
        &g.motion,
        &texels
            .iter()
            .map(|t| t.map_or([-1.0f32; 2], |t| t.motion.to_array()))
            .collect::<Vec<_>>(),
    );
}

/// One material, not emissive (what the synthetic G-buffers' material index 0 reads).
pub fn plain_materials(ctx: &Arc<Context>) -> Buffer {
    Buffer::with_data(
        ctx,
        "materials",
        &[fovea_renderer::layouts::MaterialGpu::default()],
        vk::BufferUsageFlags::STORAGE_BUFFER,
    )
    .unwrap()
}

/// Screen position of each grid texel's centre (`None`: no sample there).
pub fn texel_screens(space: &dyn SamplingSpace) -> Vec<Option<Vec2>> {
    let g = space.grid_size();
    (0..g.y)
        .flat_map(|y| (0..g.x).map(move |x| Vec2::new(x as f32 + 0.5, y as f32 + 0.5)))
        .map(|p| space.grid_to_screen(p))
        .collect()
}

pub fn assert_finite_non_negative(what: &str, pixels: &[[f32; 4]]) {
    for (i, p) in pixels.iter().enumerate() {
        assert!(
            p.iter().all(|v| v.is_finite() && *v >= 0.0),
            "{what}: texel {i} = {p:?}"
        );
    }
}

/// RMSE over RGB of the pixels `keep` selects.
pub fn rmse_where(a: &[[f32; 4]], b: &[[f32; 4]], keep: impl Fn(usize) -> bool) -> f64 {
    let (a, b): (Vec<[f32; 4]>, Vec<[f32; 4]>) = a
        .iter()
        .zip(b)
        .enumerate()
        .filter(|(i, _)| keep(*i))
        .map(|(_, (x, y))| (*x, *y))
        .unzip();
    crate::rmse(&a, &b)
}

/// Screen pixels whose 3×3 neighbourhood in the sampling grid (around the texel the pixel falls
/// in; Visual-Polar neighbours at the same angle, φ wrapping) is one surface: same material, depth
/// within 5 %, normals within ~25°, from the space's traced G-buffer. Edge texels show one surface
/// per frame where a reference averages several: aliasing at the grid's resolution, not noise.
pub fn surface_interiors(ctx: &Arc<Context>, g: &GBuffer, space: &dyn SamplingSpace) -> Vec<bool> {
    let ids: Vec<[u32; 2]> = crate::read_image(ctx, &g.ids);
    let nd: Vec<[f32; 4]> = crate::read_image(ctx, &g.normal_depth);
    let (grid, screen) = (space.grid_size(), space.screen_size());
    let rows = |c: u32| space.visual_polar().map_or(grid.y, |v| v.rows_in_column(c));
    let index = |x: u32, y: u32| (y * grid.x + x) as usize;
    let same = |i: usize, q: usize| {
        let cos = (0..3).map(|c| nd[i][c] * nd[q][c]).sum::<f32>();
        ids[q][0] != 0
            && ids[q][1] & 0xffff == ids[i][1] & 0xffff
            && (nd[q][3] - nd[i][3]).abs() < 0.05 * nd[i][3]
            && cos > 0.9
    };
    let cartesian = space.visual_polar().is_none();
    (0..screen.x * screen.y)
        .map(|p| {
            let centre = Vec2::new((p % screen.x) as f32 + 0.5, (p / screen.x) as f32 + 0.5);
            let Some(gp) = space.screen_to_grid(centre) else {
                return false;
            };
            let (tx, ty) = (gp.x as u32, gp.y as u32);
            let (n, i) = (rows(tx), index(tx, ty));
            (-1..=1i32).all(|dx| {
                let c = tx as i32 + dx;
                if c < 0 || c >= grid.x as i32 {
                    return true;
                }
                let nc = rows(c as u32) as i32;
                let row = ((ty as f32 + 0.5) * nc as f32 / n as f32) as i32;
                (-1..=1i32).all(|dy| {
                    let r = row + dy;
                    if cartesian && (r < 0 || r >= nc) {
                        return true;
                    }
                    same(i, index(c as u32, r.rem_euclid(nc) as u32))
                })
            })
        })
        .collect()
}

/// The φ-seam tests' signal: a sine once around every column (row y of column x), so a filter that
/// did not wrap on φ would see a jump where the rows end.
pub fn seam_truth(vp: &VisualPolar, x: u32, y: u32) -> f32 {
    0.5 + 0.3 * (std::f32::consts::TAU * (y as f32 + 0.5) / vp.rows_in_column(x) as f32).sin()
}

/// The seam tests' noise on texel `i` in frame `f`.
pub fn seam_noise(i: u32, f: u32) -> f32 {
    0.6 * (crate::unit_hash(i * 13 + f * 104_729) - 0.5)
}

/// The seam tests' G-buffer for frame `f`: `seam_truth` plus `seam_noise` on one face-on plane
/// at depth 5 (positions spread with the screen so BMFR's features span it).
pub fn seam_texels(vp: &VisualPolar, f: u32) -> Vec<Option<Texel>> {
    let (grid, centre) = (vp.grid_size(), vp.screen_size().as_vec2() * 0.5);
    texel_screens(vp)
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let (x, y) = (i as u32 % grid.x, i as u32 / grid.x);
            let radiance = seam_truth(vp, x, y) + seam_noise(i as u32, f);
            s.map(|s| {
                let p = (s - centre) / 64.0 * 5.0;
                Texel {
                    radiance: [radiance; 3],
                    normal: [0.0, 0.0, 1.0],
                    position: [p.x, p.y, -5.0],
                    mesh: 1,
                    motion: s,
                }
            })
        })
        .collect()
}

/// RMS error against `seam_truth` of a filtered polar grid (`out`, green channel), over columns
/// with at least 32 rows whose circle wraps (all of them in the paper's layout): the rows next to the φ = 0/2π seam, the rows at φ ≈ π, and the median
/// of 16 row bins.
#[derive(Clone, Copy, Debug)]
pub struct SeamErrors {
    pub seam: f64,
    pub opposite: f64,
    pub median: f64,
    /// Per row bin, from φ = 0.
    pub bins: [f64; 16],
}

impl SeamErrors {
    pub fn of(vp: &VisualPolar, out: &[[f32; 4]]) -> SeamErrors {
        const BINS: usize = 16;
        let grid = vp.grid_size();
        let (mut sum, mut count) = ([0f64; BINS], [0u32; BINS]);
        let (mut seam, mut seam_n, mut opposite, mut opposite_n) = (0f64, 0, 0f64, 0);
        for x in 0..grid.x {
            let n = vp.rows_in_column(x);
            // The screen-clipped layout's clipped columns have no seam: their rows end at the
            // screen's border (`ColumnArcs::wraps`).
            if n < 32 || !vp.column_arcs(x).wraps() {
                continue;
            }
            for y in 0..n {
                let e = (out[(y * grid.x + x) as usize][1] - seam_truth(vp, x, y)) as f64;
                let bin = (y as usize * BINS) / n as usize;
                sum[bin] += e * e;
                count[bin] += 1;
                if y < 2 || y + 2 >= n {
                    seam += e * e;
                    seam_n += 1;
                } else if y + 2 >= n / 2 && y < n / 2 + 2 {
                    opposite += e * e;
                    opposite_n += 1;
                }
            }
        }
        assert!(
            count.iter().all(|&c| c > 0),
            "no column with a seam and 32 rows"
        );
        let bins: [f64; BINS] = std::array::from_fn(|b| (sum[b] / count[b] as f64).sqrt());
        let mut sorted = bins;
        sorted.sort_by(f64::total_cmp);
        SeamErrors {
            seam: (seam / seam_n as f64).sqrt(),
            opposite: (opposite / opposite_n as f64).sqrt(),
            median: sorted[BINS / 2],
            bins,
        }
    }

    /// The seam filtered like any other angle: its error no larger (×1.25) than the median row
    /// bin and (×3) than the rows at φ ≈ π. A filter that stopped at the seam would average one
    /// side of the slope there: with 0.3·2π/n per row over taps reaching 8–16 rows that is a bias
    /// of 0.1–0.2 on an 80-row column (estimated, not measured), 20–40× the 0.003–0.006 measured. The φ ≈ π bound is loose
    /// because the filtered error is spatially correlated, so two zero crossings of one run differ:
    /// log-polar's SVGF measures 0.0022 at φ ≈ π and 0.0043–0.0045 in the bins beside it and the
    /// seam's (measured 2026-12-02).
    pub fn like_elsewhere(&self) -> bool {
        self.seam <= 3.0 * self.opposite && self.seam <= 1.25 * self.median
    }
}

/// Visual-Polar frames of the Cornell box at 128×144 with the gaze walking from 0.3 to 0.1 of the
/// screen (off the centre: at this size only then are whole tiles culled). Each frame goes to
/// `each(frame, renderer, over the culled tiles, over every tile)`: the same frame for a denoiser
/// over the view's tile list and one over the whole grid. Asserts that tiles were culled and that
/// the culled set moved with the gaze, so that the comparison tests something.
pub fn denoise_over_culled_tiles(
    ctx: &Arc<Context>,
    frames: u32,
    mut each: impl FnMut(u32, &Renderer, &GridFrame, &GridFrame),
) {
    let scene = crate::owned_scene("cornell-box");
    let size = UVec2::new(128, 144);
    let camera = CameraPose::from_scene_camera(&scene.cameras[0], size.x, size.y);
    let vp = VisualPolar::new(size, size.as_vec2() * 0.5, VisualPolarParams::default()).unwrap();
    let settings = RenderSettings {
        denoiser: DenoiserSettings::None,
        ..Default::default()
    };
    let mut r = Renderer::new(ctx, &scene, Box::new(vp), settings).unwrap();
    let mut previous = None;
    let mut idle_seen = Vec::new();
    for f in 0..frames {
        let gaze = size.as_vec2() * (0.3 - 0.2 * f as f32 / frames.max(2) as f32);
        r.render_frame(&FrameInput::mono(camera, f, Some(gaze)))
            .unwrap();
        let current = r.space().params();
        let buffers = crate::SpaceBuffers::new(ctx, r.space(), f, 1);
        let culled = OwnedTileList::new(ctx, r.space(), true).unwrap();
        let whole = &buffers.tiles;
        assert!(
            culled.tiles.idle.len() > whole.tiles.idle.len(),
            "frame {f}: no tile culled, nothing tested"
        );
        idle_seen.push(culled.tiles.idle.clone());
        let over_every_tile = GridFrame {
            camera_origin: camera.world_from_view.w_axis.truncate(),
            ..buffers.grid_frame(&r.view(0).gbuffer, (current, previous), &r.scene.materials)
        };
        let over_culled = GridFrame {
            tiles: culled.list(),
            ..over_every_tile
        };
        each(f, &r, &over_culled, &over_every_tile);
        previous = Some(current);
    }
    assert!(
        idle_seen.windows(2).any(|w| w[0] != w[1]),
        "the idle tiles never changed with the gaze"
    );
}

/// Asserts that each named pair of images (16-byte texels, shown as RGBA floats) holds the same
/// bits; a failure leaves both pictures and their FLIP difference behind.
pub fn assert_bit_equal(ctx: &Arc<Context>, what: &str, pairs: &[(&str, &Image, &Image)]) {
    for (name, a, b) in pairs {
        let (actual, expected) = (
            crate::read_image::<[f32; 4]>(ctx, a),
            crate::read_image::<[f32; 4]>(ctx, b),
        );
        crate::assert_pictures_equal(
            &format!("{what}, {name}"),
            &crate::Picture::hdr(a.width, a.height, &actual),
            &crate::Picture::hdr(b.width, b.height, &expected),
        );
    }
}
