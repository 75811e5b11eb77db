use super::*;
use crate::lights::sample_alias;

/// A small map with one bright texel over a dim gradient: a peaked distribution.
fn peaked(width: u32, height: u32) -> EnvironmentMap {
    let texels = (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            if (x, y) == (width / 3, height / 4) {
                Vec3::new(50.0, 40.0, 30.0)
            } else {
                Vec3::splat(0.1 + 0.05 * y as f32)
            }
        })
        .collect();
    EnvironmentMap::new(width, height, texels).unwrap()
}

/// Deterministic uniform numbers (a 64-bit LCG's top 24 bits, like the shader's resolution).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / 16777216.0
    }
}

#[test]
fn mapping_round_trips_and_faces_minus_z_at_the_centre() {
    assert!((uv_to_direction(Vec2::new(0.5, 0.5)) - Vec3::NEG_Z).length() < 1e-6);
    assert!((uv_to_direction(Vec2::new(0.0, 0.0)) - Vec3::Y).length() < 1e-6);
    // Right of the centre is +X (a camera looking down −Z sees the map unmirrored).
    assert!(uv_to_direction(Vec2::new(0.6, 0.5)).x > 0.0);
    let mut r = Lcg(7);
    for _ in 0..1000 {
        let uv = Vec2::new(r.next(), 0.001 + 0.998 * r.next());
        let back = direction_to_uv(uv_to_direction(uv));
        let du = (back.x - uv.x).abs().min(1.0 - (back.x - uv.x).abs());
        assert!(du < 1e-5 && (back.y - uv.y).abs() < 1e-5, "{uv} → {back}");
    }
}

#[test]
fn rotation_turns_the_map_about_up() {
    let mut m = peaked(16, 8);
    m.rotation = 90f32.to_radians();
    let d = Vec3::new(0.3, 0.4, -0.5).normalize();
    assert!((m.to_world(m.to_local(d)) - d).length() < 1e-6);
    // Counter-clockwise seen from above: the map's −Z (its centre) ends up at world −X.
    assert!((m.to_world(Vec3::NEG_Z) - Vec3::NEG_X).length() < 1e-6);
    assert_eq!(
        m.radiance(Vec3::NEG_X),
        m.texels[m.texel(Vec2::new(0.5, 0.5))]
    );
}

#[test]
fn pdf_integrates_to_one_over_the_sphere() {
    for map in [
        peaked(16, 8),
        peaked(7, 5),
        EnvironmentMap::from_sky(&Sky::uniform(Vec3::ONE)),
    ] {
        let d = EnvironmentDistribution::new(&map).unwrap();
        // Midpoint rule on a grid finer than the texels; dω = 2π² sin θ du dv.
        let (nu, nv) = (map.width * 8, map.height * 8);
        let mut sum = 0.0f64;
        for j in 0..nv {
            for i in 0..nu {
                let uv = Vec2::new((i as f32 + 0.5) / nu as f32, (j as f32 + 0.5) / nv as f32);
                let jac = 2.0 * PI * PI * (PI * uv.y).sin();
                sum += (d.pdf(uv_to_direction(uv)) * jac) as f64 / (nu * nv) as f64;
            }
        }
        assert!(
            (sum - 1.0).abs() < 1e-3,
            "{}×{}: ∫pdf = {sum}",
            map.width,
            map.height
        );
    }
}

#[test]
fn texel_probabilities_follow_luminance_times_solid_angle() {
    let map = peaked(16, 8);
    let d = EnvironmentDistribution::new(&map).unwrap();
    let weight = |i: usize| luminance(map.texels[i]) * map.row_solid_angle(i as u32 / 16);
    let total: f32 = (0..map.texels.len()).map(weight).sum();
    for (i, slot) in d.alias.iter().enumerate() {
        assert!(
            (slot.pdf - weight(i) / total).abs() < 1e-5 * slot.pdf,
            "texel {i}"
        );
    }
    // The alias table's own arithmetic matches `sample_alias` (the light table's, tested there).
    assert_eq!(
        d.sample_uv([0.3, 0.999, 0.5, 0.5]).0 as usize,
        sample_alias(&d.alias, 0.3 + 0.999 / d.alias.len() as f32)
    );
}

#[test]
fn sampled_texels_match_the_probabilities_chi_square() {
    let map = peaked(12, 6);
    let d = EnvironmentDistribution::new(&map).unwrap();
    let n = 400_000;
    let mut counts = vec![0u32; d.alias.len()];
    let mut moved = 0;
    let mut r = Lcg(11);
    for _ in 0..n {
        let (i, uv) = d.sample_uv([r.next(), r.next(), r.next(), r.next()]);
        // The sampled point lies in the chosen texel, and the density is that texel's.
        assert_eq!(texel_index(uv, d.width, d.height), i);
        // Through a direction and back (what MIS evaluates), the density is the sampler's, except
        // for points that rounding moves across a texel edge.
        let dir = uv_to_direction(uv);
        let expected = pdf_solid_angle(d.alias[i as usize].pdf, uv.y, d.width, d.height);
        if (d.pdf(dir) - expected).abs() > 1e-3 * expected {
            moved += 1;
        }
        counts[i as usize] += 1;
    }
    let chi2: f64 = counts
        .iter()
        .zip(&d.alias)
        .map(|(&c, s)| {
            let e = s.pdf as f64 * n as f64;
            (c as f64 - e).powi(2) / e
        })
        .sum();
    assert!(
        moved < n / 1_000,
        "{moved} samples changed texel through their direction"
    );
    // 71 degrees of freedom: the 99.9 % quantile is 114.
    assert!(chi2 < 114.0, "χ² = {chi2}");
}

#[test]
fn invalid_maps_are_refused_with_the_reason() {
    let e = |w, h, t: Vec<Vec3>| EnvironmentMap::new(w, h, t).unwrap_err();
    assert!(e(0, 4, vec![]).contains("at least 1"));
    assert!(check_size(8193, 16).unwrap_err().contains("8192×4096"));
    assert!(check_size(16, 4097).unwrap_err().contains("8192×4096"));
    assert!(e(2, 1, vec![Vec3::ONE, Vec3::new(f32::NAN, 0.0, 0.0)]).contains("texel (1, 0)"));
    assert!(e(
        2,
        2,
        vec![Vec3::ONE, Vec3::ONE, Vec3::new(0.0, -1.0, 0.0), Vec3::ONE]
    )
    .contains("texel (0, 1)"));
    assert!(e(2, 1, vec![Vec3::splat(f32::INFINITY), Vec3::ONE]).contains("finite"));
    assert!(
        EnvironmentDistribution::new(&EnvironmentMap::new(2, 1, vec![Vec3::ZERO; 2]).unwrap())
            .is_none()
    );
}

#[test]
fn baked_sky_and_halving_keep_the_light() {
    let uniform = EnvironmentMap::from_sky(&Sky::uniform(Vec3::splat(0.7)));
    assert!(uniform.texels.iter().all(|t| *t == Vec3::splat(0.7)));
    assert!((uniform.luminance_integral() - 0.7 * 4.0 * PI).abs() < 1e-3);
    let sky = Sky {
        zenith: Vec3::new(0.2, 0.3, 1.0),
        horizon: Vec3::ONE,
        ground: Vec3::splat(0.1),
    };
    let baked = EnvironmentMap::from_sky(&sky);
    assert_eq!(baked.radiance(Vec3::NEG_Y), sky.ground);
    assert!((baked.radiance(Vec3::Y) - sky.zenith).length() < 0.01);
    // Even sizes: each new texel covers exactly its four, weighted by solid angle.
    let map = peaked(16, 8);
    let half = map.halved();
    assert_eq!((half.width, half.height), (8, 4));
    let (a, b) = (map.luminance_integral(), half.luminance_integral());
    assert!((a - b).abs() < 1e-4 * a, "{a} vs {b}");
    assert_eq!(
        (
            map.halved().halved().halved().halved().width,
            peaked(17, 9).halved().height
        ),
        (1, 5)
    );
}
