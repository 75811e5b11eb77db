//! The physically based daylight sky (`--sky preetham`): Preetham, Shirley & Smits 1999, "A
//! practical analytic model for daylight" — Perez et al.'s all-weather distribution of luminance
//! and chromaticity with the paper's fits for turbidity T (its Appendix A.2), converted CIE Yxy →
//! XYZ → linear sRGB and baked into an equirectangular map so that it takes the environment map's
//! importance-sampled path like the gradient sky. Its sun is the default directional sun (the
//! disc itself is not in the map).

use fovea_renderer::scene::environment::{uv_to_direction, EnvironmentMap};
use fovea_renderer::scene::Sky;
use glam::{Vec2, Vec3};

/// A clear sky (Preetham's range is 2–10; 2–3 is clear, 6 hazy).
pub const TURBIDITY: f32 = 3.0;
/// Baked size: the sky varies with azimuth around the sun, so a 2:1 map (1.4° per texel).
pub const BAKE_SIZE: (u32, u32) = (256, 128);
/// Below the horizon: a grey ground of this share of the sky's mean radiance (like the gradient
/// sky's 0.3 at its horizon), so light from below stays weaker than from above.
const GROUND_SHARE: f32 = 0.3;

/// Perez's five coefficients for Y, x and y as linear functions of turbidity (A.2).
fn perez_coefficients(t: f32) -> [[f32; 5]; 3] {
    [
        [
            0.1787 * t - 1.4630,
            -0.3554 * t + 0.4275,
            -0.0227 * t + 5.3251,
            0.1206 * t - 2.5771,
            -0.0670 * t + 0.3703,
        ],
        [
            -0.0193 * t - 0.2592,
            -0.0665 * t + 0.0008,
            -0.0004 * t + 0.2125,
            -0.0641 * t - 0.8989,
            -0.0033 * t + 0.0452,
        ],
        [
            -0.0167 * t - 0.2608,
            -0.0950 * t + 0.0092,
            -0.0079 * t + 0.2102,
            -0.0441 * t - 1.6537,
            -0.0109 * t + 0.0529,
        ],
    ]
}

/// F(θ, γ) = (1 + A e^(B / cos θ)) (1 + C e^(Dγ) + E cos² γ); θ from the zenith, γ from the sun.
fn perez(c: &[f32; 5], cos_theta: f32, gamma: f32) -> f32 {
    // cos θ → 0 at the horizon: B < 0 makes the term vanish, the clamp only avoids 0/0.
    (1.0 + c[0] * (c[1] / cos_theta.max(1e-3)).exp())
        * (1.0 + c[2] * (c[3] * gamma).exp() + c[4] * gamma.cos().powi(2))
}

/// The zenith's luminance (kcd/m²) and chromaticity x, y for turbidity `t` and sun zenith angle `ts`.
fn zenith(t: f32, ts: f32) -> [f32; 3] {
    let chi = (4.0 / 9.0 - t / 120.0) * (std::f32::consts::PI - 2.0 * ts);
    let y_lum = (4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192;
    let (ts2, ts3) = (ts * ts, ts * ts * ts);
    let x = t * t * (0.00166 * ts3 - 0.00375 * ts2 + 0.00209 * ts)
        + t * (-0.02903 * ts3 + 0.06377 * ts2 - 0.03202 * ts + 0.00394)
        + (0.11693 * ts3 - 0.21196 * ts2 + 0.06052 * ts + 0.25886);
    let y = t * t * (0.00275 * ts3 - 0.00610 * ts2 + 0.00317 * ts)
        + t * (-0.04214 * ts3 + 0.08970 * ts2 - 0.04153 * ts + 0.00516)
        + (0.15346 * ts3 - 0.26756 * ts2 + 0.06670 * ts + 0.26688);
    [y_lum, x, y]
}

/// CIE Yxy → linear sRGB (D65 primaries).
fn yxy_to_rgb([lum, x, y]: [f32; 3]) -> Vec3 {
    let (cx, cz) = (x / y * lum, (1.0 - x - y) / y * lum);
    Vec3::new(
        3.2406 * cx - 1.5372 * lum - 0.4986 * cz,
        -0.9689 * cx + 1.8758 * lum + 0.0415 * cz,
        0.0557 * cx - 0.2040 * lum + 1.0570 * cz,
    )
    .max(Vec3::ZERO)
}

/// The Preetham sky for a sun toward `sun` (unit, above the horizon).
pub struct Preetham {
    sun: Vec3,
    coefficients: [[f32; 5]; 3],
    /// Zenith value / F(0, θs) per channel: what F(θ, γ) multiplies.
    scale: [f32; 3],
}

impl Preetham {
    pub fn new(sun: Vec3, turbidity: f32) -> Preetham {
        let coefficients = perez_coefficients(turbidity);
        let ts = sun.y.clamp(-1.0, 1.0).acos();
        let z = zenith(turbidity, ts);
        let scale = [0, 1, 2].map(|i| z[i] / perez(&coefficients[i], 1.0, ts));
        Preetham {
            sun,
            coefficients,
            scale,
        }
    }

    /// Linear sRGB radiance (kcd/m²-based units) toward unit direction `dir` at or above the horizon.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let gamma = dir.dot(self.sun).clamp(-1.0, 1.0).acos();
        let yxy = [0, 1, 2].map(|i| self.scale[i] * perez(&self.coefficients[i], dir.y, gamma));
        yxy_to_rgb(yxy)
    }
}

/// Illuminance-like irradiance (luminance-weighted) of the upper hemisphere of `map` on an
/// upward plane: ∫ L cos θ dω over the texels above the horizon.
pub fn upward_irradiance(map: &EnvironmentMap) -> f32 {
    let luminance = |c: Vec3| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
    (0..map.height)
        .map(|y| {
            let cos_theta = uv_to_direction(Vec2::new(0.5, (y as f32 + 0.5) / map.height as f32)).y;
            let row = &map.texels[(y * map.width) as usize..((y + 1) * map.width) as usize];
            let mean: f32 = row.iter().map(|&c| luminance(c)).sum::<f32>() / map.width as f32;
            if cos_theta > 0.0 {
                mean * cos_theta * map.row_solid_angle(y) * map.width as f32
            } else {
                0.0
            }
        })
        .sum()
}

/// The Preetham sky for a sun at `sun` (unit) baked into a map, scaled so that its irradiance on
/// an upward plane equals the gradient sky's of the same intensity (`--sky-intensity` means the
/// same amount of sky light for both models); the ground below the horizon is grey.
pub fn preetham_map(sun: Vec3, intensity: f32) -> EnvironmentMap {
    let sky = Preetham::new(sun, TURBIDITY);
    let (width, height) = BAKE_SIZE;
    let direction = |x: u32, y: u32| {
        uv_to_direction(Vec2::new(
            (x as f32 + 0.5) / width as f32,
            (y as f32 + 0.5) / height as f32,
        ))
    };
    let below: Vec<bool> = (0..height).map(|y| direction(0, y).y < 0.0).collect();
    // The ground rows are filled once the sky's scale is known.
    let texels = (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| {
            if below[y as usize] {
                Vec3::ZERO
            } else {
                sky.radiance(direction(x, y))
            }
        })
        .collect();
    let mut map = EnvironmentMap::new(width, height, texels)
        .expect("a finite, non-negative bake of a valid size");
    let target = upward_irradiance(&EnvironmentMap::from_sky(&default_sky(intensity)));
    let scale = if intensity > 0.0 {
        target / upward_irradiance(&map)
    } else {
        0.0
    };
    let rows = map.texels.chunks_exact(width as usize).zip(&below);
    let (sum, count) = rows
        .filter(|(_, &b)| !b)
        .fold((Vec3::ZERO, 0usize), |(s, n), (row, _)| {
            (s + row.iter().sum::<Vec3>(), n + row.len())
        });
    let mean = sum / count.max(1) as f32 * scale * GROUND_SHARE;
    let ground = Vec3::splat((mean.x + mean.y + mean.z) / 3.0);
    for (row, &b) in map.texels.chunks_exact_mut(width as usize).zip(&below) {
        row.iter_mut()
            .for_each(|c| *c = if b { ground } else { *c * scale });
    }
    map
}

/// The gradient sky is [`Sky`]; this names the models `--sky` takes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SkyModel {
    /// The horizon-to-zenith gradient (`default_sky`).
    #[default]
    Gradient,
    /// Preetham et al. 1999 around the default sun.
    Preetham,
}

impl SkyModel {
    pub const NAMES: &'static str = "gradient, preetham";

    pub fn parse(name: &str) -> anyhow::Result<SkyModel> {
        match name {
            "gradient" => Ok(SkyModel::Gradient),
            "preetham" => Ok(SkyModel::Preetham),
            other => anyhow::bail!("sky model '{other}' is not one of {}", Self::NAMES),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            SkyModel::Gradient => "gradient",
            SkyModel::Preetham => "preetham",
        }
    }
}

/// The unit vector toward the sun at `azimuth` (from +Z toward +X) and `elevation` (degrees).
pub fn sun_direction(azimuth_deg: f32, elevation_deg: f32) -> Vec3 {
    let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    Vec3::new(az.sin() * el.cos(), el.sin(), az.cos() * el.cos())
}

/// The default sky, radiance × `intensity`: a pale horizon (1, 0.97, 0.92), a blue zenith
/// (0.35, 0.55, 1.0) and a dim grey ground (0.3) below the horizon, so that light from below
/// (an open floor's bounce) stays weaker than from above.
pub fn default_sky(intensity: f32) -> Sky {
    Sky {
        zenith: Vec3::new(0.35, 0.55, 1.0) * intensity,
        horizon: Vec3::new(1.0, 0.97, 0.92) * intensity,
        ground: Vec3::splat(0.3) * intensity,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zenith_is_bluish_and_brightens_with_the_sun_and_the_sky_peaks_around_it() {
        // The zenith brightens as the sun rises and stays a bluish white (x, y below D65's 0.313, 0.329).
        let low = zenith(TURBIDITY, 80f32.to_radians());
        let high = zenith(TURBIDITY, 30f32.to_radians());
        assert!(high[0] > low[0] && low[0] > 0.0, "{low:?} {high:?}");
        for [_, x, y] in [low, high] {
            assert!(
                (0.2..0.313).contains(&x) && (0.2..0.329).contains(&y),
                "{x} {y}"
            );
        }
        let sun = sun_direction(30.0, 30.0);
        let sky = Preetham::new(sun, TURBIDITY);
        let zenith_rgb = sky.radiance(Vec3::Y);
        assert!(
            zenith_rgb.z > zenith_rgb.x,
            "the zenith should be blue: {zenith_rgb}"
        );
        // Near the sun brighter than opposite it at the same elevation (the circumsolar peak).
        let toward = sun_direction(30.0, 40.0);
        let away = sun_direction(210.0, 40.0);
        assert!(sky.radiance(toward).length() > 3.0 * sky.radiance(away).length());
        // Symmetric about the sun's vertical plane.
        let (l, r) = (
            sky.radiance(sun_direction(10.0, 20.0)),
            sky.radiance(sun_direction(50.0, 20.0)),
        );
        assert!(
            (l - r).abs().max_element() < 1e-3 * l.max_element(),
            "{l} vs {r}"
        );
    }

    #[test]
    fn baked_map_has_the_gradient_skys_irradiance_and_a_grey_ground() {
        for (azimuth, elevation) in [(30.0, 60.0), (200.0, 15.0)] {
            let map = preetham_map(sun_direction(azimuth, elevation), 0.5);
            let target = upward_irradiance(&EnvironmentMap::from_sky(&default_sky(0.5)));
            assert!((upward_irradiance(&map) - target).abs() < 1e-3 * target);
            let below = map.radiance(-Vec3::Y);
            assert!(
                below.x == below.y && below.y == below.z && below.x > 0.0,
                "{below}"
            );
            assert!(
                map.radiance(sun_direction(azimuth, elevation.min(80.0)))
                    .length()
                    > map.radiance(Vec3::Y).length() * 0.5
            );
        }
        assert!(preetham_map(Vec3::Y, 0.0)
            .texels
            .iter()
            .all(|&c| c == Vec3::ZERO));
    }
}
