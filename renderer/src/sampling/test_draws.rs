//! For the density tests of the polar spaces: samples drawn at random with the density a grid
//! stands for (a kept texel uniformly at random, a position in it uniformly at random, mapped to
//! the screen), so counts per ring are multinomial and Pearson's χ² (`fovea_test_kit::chi2`)
//! applies. Enough draws that a ring holding a few thousand shows a density error of a few per
//! cent, few enough for a unit test.

use super::VisualPolar;
use glam::Vec2;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

pub const DENSITY_DRAWS: usize = 200_000;

/// `n` screen positions drawn as described above (seeded: the same every run).
pub fn draw_screen_samples(s: &VisualPolar, n: usize, seed: u64) -> Vec<Vec2> {
    let grid = s.grid_size();
    // Kept texels in column order, so a uniform index picks one.
    let mut first_of_column = Vec::with_capacity(grid.x as usize);
    let mut kept = 0u64;
    for c in 0..grid.x {
        first_of_column.push(kept);
        kept += s.rows_in_column(c) as u64;
    }
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let k = rng.random_range(0..kept);
            let c = first_of_column.partition_point(|&f| f <= k) - 1;
            let row = k - first_of_column[c];
            s.vp_to_screen(Vec2::new(
                c as f32 + rng.random::<f32>(),
                row as f32 + rng.random::<f32>(),
            ))
        })
        .collect()
}
