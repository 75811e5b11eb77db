//! The screen-clipped Visual-Polar layout's geometry (beyond the paper): the part of a
//! circle around the gaze that lies on the screen, as up to 4 angular intervals, and the map
//! between a column's arc position and φ. `shaders/sampling/visual_polar_clipped.glsl` mirrors
//! `ColumnArcs::{phi_of_arc, arc_of_phi}` op for op; the intervals themselves are computed only
//! here (per frame, on the CPU) and handed to the GPU as a per-column table, so both sides map
//! with the very same f32 numbers.
//!
//! A column's rows are laid along the concatenated intervals: arc position a ∈ [0, A) (A = total
//! on-screen angle), interval i covering a ∈ [end[i−1], end[i]) (end[−1] = 0) at φ = start[i] +
//! (a − end[i−1]). A circle entirely on the screen (or entirely off it) is one full interval
//! starting at φ = 0, which is exactly the paper's layout, φ wrapping.

use glam::{UVec2, Vec2};
use std::f32::consts::TAU;

/// On-screen intervals (and gaps between them) shorter than this (radians) are dropped: a circle
/// grazing a border would otherwise get slivers holding whole rows, or a gap too thin to matter.
const MIN_ARC: f64 = 1e-4;

/// The on-screen part of one column's circle. Unused slots (fewer than 4 intervals) repeat the
/// total in `end` and the end angle of the last interval in `start`, so lookups need no count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColumnArcs {
    /// φ where each interval starts, in [0, 2π).
    pub start: [f32; 4],
    /// Cumulative arc length at each interval's end; `end[3]` is the total A.
    pub end: [f32; 4],
}

impl ColumnArcs {
    /// The whole circle from φ = 0: the paper's layout.
    pub const FULL: ColumnArcs = ColumnArcs {
        start: [0.0; 4],
        end: [TAU; 4],
    };

    /// Total on-screen angle A (2π for a full circle).
    pub fn total(&self) -> f32 {
        self.end[3]
    }

    /// Full circles wrap on φ; clipped arcs clamp at their ends.
    pub fn wraps(&self) -> bool {
        self.end[3] >= TAU
    }

    /// Number of intervals (1 to 4).
    pub fn count(&self) -> usize {
        1 + (1..4).filter(|&i| self.end[i] > self.end[i - 1]).count()
    }

    /// Arc position where interval `i` begins.
    pub fn arc_start(&self, i: usize) -> f32 {
        if i == 0 {
            0.0
        } else {
            self.end[i - 1]
        }
    }

    /// Continuous row (level-0 units) of arc position `a` in a column with `n` rows.
    pub fn arc_row(&self, a: f32, n: f32) -> f32 {
        a / self.total() * n
    }

    /// The interval a continuous row `y` belongs to (before the first: the first; past the last:
    /// the last). The φ mips average only rows of one interval and the remap reads only those of
    /// the pixel's, so nothing is blended across a gap.
    pub fn interval_of_row(&self, y: f32, n: f32) -> usize {
        (1..4)
            .rev()
            .find(|&j| self.end[j] > self.end[j - 1] && y >= self.arc_row(self.end[j - 1], n))
            .unwrap_or(0)
    }

    /// The column's two RGBA32F texels in the GPU table: starts, then ends.
    pub fn texels(&self) -> [[f32; 4]; 2] {
        [self.start, self.end]
    }

    /// Arc position → φ. Full circles take any `a` (φ = a, wrapping through cos/sin); clipped
    /// arcs clamp `a` to [0, A].
    pub fn phi_of_arc(&self, a: f32) -> f32 {
        if self.wraps() {
            return a;
        }
        let a = a.clamp(0.0, self.total());
        let i =
            (a >= self.end[0]) as usize + (a >= self.end[1]) as usize + (a >= self.end[2]) as usize;
        self.start[i] + (a - self.arc_start(i))
    }

    /// φ ∈ [0, 2π) → (arc position, interval, gap): an angle in a gap (the circle at the pixel's
    /// own radius reaches a little further than at the column's centre radius) clamps to the
    /// nearest interval end, so the position is continuous in φ; `gap` is how far it moved
    /// (radians, 0 inside the arcs).
    pub fn arc_of_phi(&self, phi: f32) -> (f32, usize, f32) {
        if self.wraps() {
            return (phi, 0, 0.0);
        }
        let (mut best, mut best_a, mut best_i) = (f32::INFINITY, 0.0, 0);
        for i in 0..4 {
            let c = self.arc_start(i);
            let len = self.end[i] - c;
            if len > 0.0 {
                let mut d = phi - self.start[i];
                if d < 0.0 {
                    d += TAU;
                }
                if d <= len {
                    return (c + d, i, 0.0);
                }
                let (to_end, to_start) = (d - len, TAU - d);
                if to_end < best {
                    (best, best_a, best_i) = (to_end, self.end[i], i);
                }
                if to_start < best {
                    (best, best_a, best_i) = (to_start, c, i);
                }
            }
        }
        (best_a, best_i, best)
    }
}

/// The on-screen part of the circle (centre `gaze`, radius `r` pixels) within the screen
/// rectangle [0, w] × [0, h]: each edge the circle crosses cuts out the arc around that edge's
/// outward normal (half-width acos(d/r), d = gaze-to-edge distance); what remains is at most 4
/// intervals. A circle that stays on the screen, or lies entirely off it, is `FULL`.
pub fn on_screen_arcs(gaze: Vec2, r: f32, screen: UVec2) -> ColumnArcs {
    use std::f64::consts::{FRAC_PI_2, PI, TAU as TAU64};
    let (g, s, r) = (gaze.as_dvec2(), screen.as_dvec2(), r as f64);
    if r.is_nan() || r <= 0.0 || !g.is_finite() {
        return ColumnArcs::FULL;
    }
    // Cut arcs as [lo, hi) within [0, 2π), split where they cross φ = 0. Fixed arrays, not
    // vectors: the renderer rebuilds every column's arcs each frame and must not allocate.
    let mut cuts = [(0.0f64, 0.0f64); 8];
    let mut n_cuts = 0;
    let edges = [
        (0.0, s.x - g.x),
        (FRAC_PI_2, s.y - g.y),
        (PI, g.x),
        (3.0 * FRAC_PI_2, g.y),
    ];
    for (normal, d) in edges {
        if d >= r {
            continue;
        }
        let half = (d / r).max(-1.0).acos();
        if half >= PI {
            return ColumnArcs::FULL; // the whole circle lies beyond this edge
        }
        let lo = (normal - half).rem_euclid(TAU64);
        let hi = lo + 2.0 * half;
        if hi > TAU64 {
            cuts[n_cuts] = (lo, TAU64);
            cuts[n_cuts + 1] = (0.0, hi - TAU64);
            n_cuts += 2;
        } else {
            cuts[n_cuts] = (lo, hi);
            n_cuts += 1;
        }
    }
    if n_cuts == 0 {
        return ColumnArcs::FULL;
    }
    let cuts = &mut cuts[..n_cuts];
    cuts.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    // The complement of the merged cuts, walking 0 → 2π: (start, length), at most 5.
    let mut on = [(0.0f64, 0.0f64); 5];
    let mut n_on = 0;
    let mut at = 0.0;
    for &(lo, hi) in cuts.iter() {
        if lo > at {
            on[n_on] = (at, lo - at);
            n_on += 1;
        }
        at = at.max(hi);
    }
    if at < TAU64 {
        on[n_on] = (at, TAU64 - at);
        n_on += 1;
    }
    let mut on = &mut on[..n_on];
    // An interval ending at 2π continues the one starting at 0.
    if on.len() >= 2 && on[0].0 == 0.0 {
        let last = on.len() - 1;
        if on[last].0 + on[last].1 >= TAU64 {
            on[last].1 += on[0].1;
            on = &mut on[1..];
        }
    }
    // Drop slivers (keeping the order).
    let mut kept = 0;
    for i in 0..on.len() {
        if on[i].1 >= MIN_ARC {
            on[kept] = on[i];
            kept += 1;
        }
    }
    let on = &on[..kept];
    let total: f64 = on.iter().map(|&(_, len)| len).sum();
    if on.is_empty() || total > TAU64 - MIN_ARC {
        return ColumnArcs::FULL;
    }
    debug_assert!(
        on.len() <= 4,
        "a circle meets a rectangle in at most 4 arcs: {on:?}"
    );
    let mut arcs = ColumnArcs {
        start: [0.0; 4],
        end: [0.0; 4],
    };
    let mut cumulative = 0.0;
    let mut last_end = 0.0;
    for i in 0..4 {
        match on.get(i) {
            Some(&(start, len)) => {
                cumulative += len;
                arcs.start[i] = start as f32 % TAU;
                arcs.end[i] = cumulative as f32;
                last_end = (start + len).rem_euclid(TAU64);
            }
            None => {
                arcs.start[i] = last_end as f32 % TAU;
                arcs.end[i] = cumulative as f32;
            }
        }
    }
    arcs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{VisualPolar, VpLayout};
    use glam::DVec2;

    const SCREEN: UVec2 = UVec2::new(1280, 1440);

    fn on_screen(p: DVec2) -> bool {
        p.x >= -1e-3 && p.y >= -1e-3 && p.x <= 1280.001 && p.y <= 1440.001
    }

    /// Dense angle sweep: an angle is inside the arcs exactly when its point is on the screen.
    #[test]
    fn arcs_are_the_on_screen_part_of_the_circle() {
        let gazes = [
            (640.0, 720.0),
            (10.0, 10.0),
            (200.0, 300.0),
            (200.0, 720.0),
            (0.0, 720.0),
            (1270.0, 5.0),
            (-50.0, 700.0),
            (640.0, 1500.0),
        ];
        let mut counts = [0usize; 5];
        for (gx, gy) in gazes {
            let gaze = Vec2::new(gx, gy);
            for r in [
                5.0f32, 300.0, 650.0, 700.0, 730.0, 800.0, 1000.0, 1300.0, 1500.0, 1900.0, 2500.0,
            ] {
                let arcs = on_screen_arcs(gaze, r, SCREEN);
                counts[arcs.count()] += 1;
                assert!(arcs.end.windows(2).all(|w| w[0] <= w[1]), "{arcs:?}");
                let steps = 20_000;
                let mut on_count = 0;
                for k in 0..steps {
                    let phi = (k as f64 + 0.5) / steps as f64 * std::f64::consts::TAU;
                    let p = gaze.as_dvec2() + r as f64 * DVec2::new(phi.cos(), phi.sin());
                    let (a, _, gap) = arcs.arc_of_phi(phi as f32);
                    let back = (arcs.phi_of_arc(a) - phi as f32).rem_euclid(TAU);
                    let inside = arcs.wraps() || back.min(TAU - back) < 1e-4;
                    assert!((gap == 0.0) == inside || gap < 1e-4, "gap {gap} at φ {phi}");
                    on_count += on_screen(p) as usize;
                    if arcs.wraps() {
                        continue;
                    }
                    // Away from the crossings (1e-3 rad), membership and the screen agree.
                    let near_crossing = (0..arcs.count()).any(|i| {
                        let s = arcs.start[i] as f64;
                        let e = s + (arcs.end[i] - arcs.arc_start(i)) as f64;
                        let dist = |x: f64| {
                            let d = (phi - x).rem_euclid(std::f64::consts::TAU);
                            d.min(std::f64::consts::TAU - d)
                        };
                        dist(s) < 1e-3 || dist(e) < 1e-3
                    });
                    if !near_crossing {
                        assert_eq!(inside, on_screen(p), "gaze {gaze} r {r} φ {phi}: {arcs:?}");
                    }
                }
                // Full circles are either all on screen or all off.
                if arcs.wraps() {
                    assert!(
                        on_count < 10 || on_count > steps - 10,
                        "gaze {gaze} r {r}: {on_count}"
                    );
                } else {
                    let share = arcs.total() as f64 / std::f64::consts::TAU;
                    assert!(
                        (share - on_count as f64 / steps as f64).abs() < 1e-3,
                        "gaze {gaze} r {r}"
                    );
                }
            }
        }
        // The sweep saw 1, 2, 3 and 4 intervals.
        assert!(
            counts[1..].iter().all(|&c| c > 0),
            "interval counts {counts:?}"
        );
    }

    fn clipped(w: u32, h: u32, gaze: Vec2) -> VisualPolar {
        let params = crate::sampling::VisualPolarParams {
            layout: VpLayout::ScreenClipped,
            ..Default::default()
        };
        VisualPolar::new(UVec2::new(w, h), gaze, params).unwrap()
    }

    fn gazes(w: u32, h: u32) -> [Vec2; 4] {
        let s = Vec2::new(w as f32, h as f32);
        [
            s * 0.5,
            s * Vec2::new(200.0 / 1280.0, 300.0 / 1440.0),
            Vec2::splat(10.0),
            Vec2::new(0.0, s.y * 0.45),
        ]
    }

    /// Every texel centre of the screen-clipped layout lies on the screen, the sample count is
    /// the paper's, and full-circle columns map exactly as the paper's layout does.
    #[test]
    fn texel_centres_are_on_screen_and_full_columns_are_the_papers() {
        for (w, h) in [(1280u32, 1440u32), (160, 180)] {
            for gaze in gazes(w, h) {
                let vp = clipped(w, h, gaze);
                let paper = VisualPolar::new(vp.screen(), gaze, Default::default()).unwrap();
                assert_eq!(vp.sample_count(), paper.sample_count());
                assert!(crate::sampling::params_select_clipped_layout(
                    &vp.sampling_params()
                ));
                assert!(!crate::sampling::params_select_clipped_layout(
                    &paper.sampling_params()
                ));
                let columns = 2 * paper.grid_size().x as usize;
                assert!(paper.column_table()[..columns]
                    .chunks(2)
                    .all(|t| t[0] == [0.0; 4] && t[1] == [TAU; 4]));
                let (grid, mut off, mut full_columns) = (vp.grid_size(), 0, 0);
                for x in 0..grid.x {
                    let arcs = vp.column_arcs(x);
                    full_columns += arcs.wraps() as u32;
                    for y in 0..vp.rows_in_column(x) {
                        let g = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                        let p = vp.vp_to_screen(g);
                        // Centres lie on their column's centre circle, inside its arcs: on screen
                        // up to f32 rounding.
                        off += (p.x < -1e-3
                            || p.y < -1e-3
                            || p.x > w as f32 + 1e-3
                            || p.y > h as f32 + 1e-3) as u32;
                        if arcs.wraps() {
                            assert!(
                                (p - paper.vp_to_screen(g)).length() < 1e-4,
                                "full column {x} differs from the paper's"
                            );
                        }
                    }
                }
                assert_eq!(off, 0, "{w}x{h} gaze {gaze}: texel centres off the screen");
                assert!(
                    full_columns < grid.x,
                    "{w}x{h} gaze {gaze}: some circle must leave the screen"
                );
            }
        }
    }

    /// screen → grid → screen for on-screen points (those whose angle lies outside their column's
    /// arcs clamp, by design; they lie within a column's radial extent of the border) and
    /// grid → screen → grid for kept texels.
    #[test]
    fn clipped_round_trips() {
        let mut seed = 7u64;
        let mut rand = move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 40) as f32 / (1u64 << 24) as f32
        };
        for (w, h) in [(1280u32, 1440u32), (640, 720)] {
            for gaze in gazes(w, h) {
                let vp = clipped(w, h, gaze);
                let grid = vp.grid_size();
                let (mut worst, mut clamped) = (0f32, 0);
                for _ in 0..10_000 {
                    let p = Vec2::new(rand() * w as f32, rand() * h as f32);
                    let g = vp.screen_to_vp(p);
                    let col = vp.column_of(g.x);
                    assert!(
                        g.y >= 0.0 && g.y < vp.rows_in_column(col) as f32,
                        "{p} → {g}"
                    );
                    let back = vp.vp_to_screen(g);
                    let err = (back - p).length();
                    if err < 5e-3 {
                        worst = worst.max(err);
                        continue;
                    }
                    // A clamped angle: back lands on the border side of p, no farther than the
                    // column's radial extent (one column step along ρ).
                    clamped += 1;
                    let u = |x: f32| x / grid.x as f32;
                    let extent = vp.r_of_u(u(col as f32 + 1.0)) - vp.r_of_u(u(col as f32));
                    let border = p.x.min(p.y).min(w as f32 - p.x).min(h as f32 - p.y);
                    assert!(
                        border <= extent + 1e-2,
                        "{w}x{h} gaze {gaze}: {p} → {g} → {back} ({border} px from the border)"
                    );
                }
                println!("{w}x{h} gaze {gaze}: screen→grid→screen worst {worst:.2e} px, {clamped} of 10000 clamped at the border");
                assert!(clamped < 300, "{clamped} clamped");
                for _ in 0..10_000 {
                    let x = rand() * grid.x as f32;
                    if x.fract() < 1e-3 || x.fract() > 1.0 - 1e-3 {
                        continue;
                    }
                    let n = vp.rows_in_column(x as u32) as f32;
                    let y = rand() * n;
                    let p = vp.vp_to_screen(Vec2::new(x, y));
                    if (p - gaze).length() < 1.0 {
                        continue;
                    }
                    let g = vp.screen_to_vp(p);
                    let arcs = vp.column_arcs(x as u32);
                    let dy = (g.y - y).abs();
                    let dy = if arcs.wraps() { dy.min(n - dy) } else { dy };
                    // φ compared as arc length on screen: a short corner arc packs many rows
                    // into few pixels, so rows are the wrong unit there.
                    let arc_px = dy / n * arcs.total() * (p - gaze).length();
                    assert!(
                        (g.x - x).abs() < 2e-3 && arc_px < 5e-3,
                        "({x},{y}) → {p} → {g}: {arc_px} px"
                    );
                }
            }
        }
    }

    #[test]
    fn arc_position_and_phi_invert_each_other() {
        let arcs = on_screen_arcs(Vec2::new(640.0, 720.0), 800.0, SCREEN);
        assert_eq!(arcs.count(), 4);
        for k in 0..1000 {
            let a = (k as f32 + 0.5) / 1000.0 * arcs.total();
            let phi = arcs.phi_of_arc(a).rem_euclid(TAU);
            let (back, i, _) = arcs.arc_of_phi(phi);
            assert!((back - a).abs() < 1e-5, "a {a} → φ {phi} → {back}");
            assert!(arcs.arc_start(i) <= back && back <= arcs.end[i]);
        }
        // A gap angle clamps to the nearer end: φ = 0 points at the right edge, the middle of a cut.
        let (a, i, gap) = arcs.arc_of_phi(0.01);
        assert!(a == arcs.arc_start(i) || a == arcs.end[i]);
        assert!(
            gap > 0.01 && (arcs.phi_of_arc(a) - 0.01 - gap).abs() < 1e-5,
            "gap {gap}: φ {}",
            arcs.phi_of_arc(a)
        );
        let (a2, _, _) = arcs.arc_of_phi(TAU - 0.01);
        assert!(a != a2, "the two sides of a cut clamp to different ends");
        assert_eq!(ColumnArcs::FULL.arc_of_phi(1.5), (1.5, 0, 0.0));
        assert_eq!(ColumnArcs::FULL.phi_of_arc(7.0), 7.0);
    }
}
