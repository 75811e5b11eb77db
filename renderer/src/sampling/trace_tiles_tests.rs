use super::*;
use crate::sampling::{CompositeMode, InverseCdf, LogPolarParams, RadialLaw, VisualPolarParams};
use glam::IVec2;

/// trace.comp's `far_off_screen` for the sample of `texel` at `jitter`, through the Rust mapping.
fn culled_on_gpu(vp: &VisualPolar, texel: IVec2, jitter: Vec2) -> bool {
    let screen = vp.vp_to_screen(texel.as_vec2() + jitter);
    let size = SamplingSpace::screen_size(vp).as_vec2();
    let outside = (-screen).max(screen - size).max(Vec2::ZERO);
    if outside == Vec2::ZERO {
        return false;
    }
    let mut footprint = 0.0f32;
    for step in [IVec2::X, IVec2::Y] {
        let neighbour = if vp.is_valid_texel(texel + step) {
            texel + step
        } else {
            texel - step
        };
        footprint =
            footprint.max((vp.vp_to_screen(neighbour.as_vec2() + jitter) - screen).length());
    }
    let footprint = if footprint > 0.0 { footprint } else { 1.0 };
    outside.x.max(outside.y) > CULL_FOOTPRINTS * footprint + CULL_PIXELS
}

fn unpack(tile: u32) -> UVec2 {
    UVec2::new(tile & 0xffff, tile >> 16)
}

fn check(vp: &VisualPolar) -> TraceTiles {
    let mut tiles = TraceTiles::default();
    visual_polar_tiles(vp, true, &mut tiles);
    let grid = vp.grid_size();
    let n = tile_count(grid);
    assert_eq!(tiles.live.len() + tiles.idle.len(), (n.x * n.y) as usize);
    let jitters: Vec<Vec2> = (0..5)
        .flat_map(|i| (0..5).map(move |j| Vec2::new(i as f32, j as f32) * 0.2499))
        .collect();
    let mut culled = 0;
    for &tile in &tiles.idle {
        let origin = unpack(tile) * TRACE_TILE;
        for y in origin.y..(origin.y + TRACE_TILE).min(grid.y) {
            for x in origin.x..(origin.x + TRACE_TILE).min(grid.x) {
                let texel = IVec2::new(x as i32, y as i32);
                if !vp.is_valid_texel(texel) {
                    continue;
                }
                culled += 1;
                for &j in &jitters {
                    assert!(
                        culled_on_gpu(vp, texel, j),
                        "tile {:?}: texel {texel} at jitter {j} would be traced (gaze {})",
                        unpack(tile),
                        vp.gaze()
                    );
                }
            }
        }
    }
    assert_eq!(tiles.culled_samples, culled);
    tiles
}

#[test]
fn idle_tiles_hold_no_sample_the_tracer_would_trace() {
    let screen = UVec2::new(640, 720);
    let laws = [
        VisualPolarParams::default(),
        VisualPolarParams {
            inverse_cdf: InverseCdf::Exact,
            ..Default::default()
        },
        VisualPolarParams {
            radial: RadialLaw::LogPolar(LogPolarParams::default()),
            ..Default::default()
        },
        VisualPolarParams {
            radial: RadialLaw::Composite(CompositeMode::Composite.params(1000.0)),
            ..Default::default()
        },
    ];
    for params in laws {
        for gaze in [
            Vec2::new(320.0, 360.0),
            Vec2::new(32.0, 36.0),
            Vec2::new(600.0, 100.0),
            Vec2::new(0.0, 719.0),
        ] {
            check(&VisualPolar::new(screen, gaze, params).unwrap());
        }
    }
    // The smallest test screens too (footprints of several pixels against the margin).
    check(
        &VisualPolar::new(
            UVec2::new(64, 72),
            Vec2::new(6.4, 7.2),
            VisualPolarParams::default(),
        )
        .unwrap(),
    );
}

#[test]
fn the_centred_gaze_skips_the_clipped_fovea_and_the_far_corners_of_the_circle() {
    let vp = VisualPolar::new(
        UVec2::new(640, 720),
        Vec2::new(320.0, 360.0),
        VisualPolarParams::default(),
    )
    .unwrap();
    let tiles = check(&vp);
    let all = tiles.live.len() + tiles.idle.len();
    let clipped = tiles.idle.len()
        - tiles
            .idle
            .iter()
            .filter(|&&t| {
                (0..TRACE_TILE)
                    .any(|dx| vp.rows_in_column(unpack(t).x * TRACE_TILE + dx) == vp.grid_size().y)
            })
            .count();
    assert!(clipped * 20 > all, "{clipped} clipped of {all} tiles");
    assert!(
        tiles.culled_samples as u64 * 30 > vp.sample_count(),
        "{} culled of {}",
        tiles.culled_samples,
        vp.sample_count()
    );
    // Without culling only the clipped tiles are idle, and the screen-clipped layout culls nothing.
    let mut plain = TraceTiles::default();
    visual_polar_tiles(&vp, false, &mut plain);
    assert_eq!((plain.culled_samples, plain.idle.len()), (0, clipped));
    let clipped_layout = VisualPolar::new(
        UVec2::new(640, 720),
        Vec2::new(32.0, 36.0),
        VisualPolarParams {
            layout: VpLayout::ScreenClipped,
            ..Default::default()
        },
    )
    .unwrap();
    let mut on_screen = TraceTiles::default();
    visual_polar_tiles(&clipped_layout, true, &mut on_screen);
    assert_eq!(on_screen.culled_samples, 0);
}
