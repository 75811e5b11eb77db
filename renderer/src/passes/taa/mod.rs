//! Temporal anti-aliasing (Karis 2014; denoisers.md): the tracer jitters each frame by a
//! Halton(2, 3) offset inside its texel and a resolve blends the frame into a reprojected
//! history. It runs in the sampling grid after the denoiser (`grid`, the paper's place) or, for
//! the Visual-Polar way back, on the remapped screen image before the foveated blur (`screen`).
//! It is no denoiser: it filters over time what the tracer jittered, whatever ran before it.

mod grid;
mod screen;

pub use grid::Taa;
pub use screen::ScreenTaa;

use crate::error::{Error, Result};
use glam::Vec2;

/// Filter parameters (`Default`, and a render profile's `[taa]` keys' defaults).
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TaaSettings {
    /// Blend weight of the current frame (the history keeps 1 − this), before luma weighting.
    pub current_weight: f32,
    /// Length of the Halton(2, 3) jitter cycle.
    pub jitter_points: u32,
}

impl Default for TaaSettings {
    fn default() -> Self {
        TaaSettings {
            current_weight: 0.1,
            jitter_points: 16,
        }
    }
}

/// The jitter cycles accepted: fewer points leave visible aliasing, more gain nothing at a ≈ 0.1
/// blend weight (the history forgets them before the cycle ends).
pub const JITTER_POINTS: std::ops::RangeInclusive<u32> = 8..=16;

impl TaaSettings {
    pub fn validate(&self) -> Result<()> {
        let w = self.current_weight;
        if !(w.is_finite() && w > 0.0 && w <= 1.0) {
            return Err(Error::Invalid(format!(
                "taa: current_weight must be in (0, 1], got {w}"
            )));
        }
        if !JITTER_POINTS.contains(&self.jitter_points) {
            return Err(Error::Invalid(format!(
                "taa: jitter_points must be in {}..={}, got {}",
                JITTER_POINTS.start(),
                JITTER_POINTS.end(),
                self.jitter_points
            )));
        }
        Ok(())
    }

    /// This frame's sample position inside the texel, in [0, 1)²: point `frame % jitter_points`
    /// of Halton(2, 3) (indices from 1), shifted so that the cycle's mean is the texel centre.
    pub fn jitter(&self, frame_index: u32) -> Vec2 {
        let n = self.jitter_points;
        let point = |i: u32| Vec2::new(radical_inverse(i + 1, 2), radical_inverse(i + 1, 3));
        let mean = (0..n).map(point).sum::<Vec2>() / n as f32;
        (point(frame_index % n) - mean + 0.5).clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON))
    }
}

fn radical_inverse(mut i: u32, base: u32) -> f32 {
    let (mut f, mut r) = (1.0f32, 0.0f32);
    while i > 0 {
        f /= base as f32;
        r += f * (i % base) as f32;
        i /= base;
    }
    r
}

/// Where TAA runs (`fovea render --taa`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum TaaMode {
    #[default]
    Off,
    /// In the sampling grid (`vp`; for Cartesian that is the screen).
    SamplingGrid(TaaSettings),
    /// After the remap, in screen space (`screen`; `taa_screen`). For Cartesian the sampling
    /// grid is the screen, so this is the sampling-grid filter.
    Screen(TaaSettings),
}

impl TaaMode {
    /// The names `parse` accepts.
    pub const NAMES: &'static [&'static str] = &["off", "vp", "screen"];

    pub fn parse(name: &str) -> Result<TaaMode> {
        match name {
            "off" => Ok(TaaMode::Off),
            "vp" => Ok(TaaMode::SamplingGrid(TaaSettings::default())),
            "screen" => Ok(TaaMode::Screen(TaaSettings::default())),
            other => Err(Error::Invalid(format!(
                "taa '{other}': expected one of {}",
                Self::NAMES.join(", ")
            ))),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            TaaMode::Off => "off",
            TaaMode::SamplingGrid(_) => "vp",
            TaaMode::Screen(_) => "screen",
        }
    }

    pub fn settings(&self) -> Option<&TaaSettings> {
        match self {
            TaaMode::Off => None,
            TaaMode::SamplingGrid(s) | TaaMode::Screen(s) => Some(s),
        }
    }

    /// The same mode with other filter parameters (a render profile's `[taa]`).
    pub fn with_settings(self, settings: TaaSettings) -> TaaMode {
        match self {
            TaaMode::Off => TaaMode::Off,
            TaaMode::SamplingGrid(_) => TaaMode::SamplingGrid(settings),
            TaaMode::Screen(_) => TaaMode::Screen(settings),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton_jitter_is_centred_inside_the_texel_and_cycles() {
        for n in JITTER_POINTS {
            let s = TaaSettings {
                jitter_points: n,
                ..Default::default()
            };
            let points: Vec<Vec2> = (0..n).map(|f| s.jitter(f)).collect();
            assert!(
                points
                    .iter()
                    .all(|p| p.cmpge(Vec2::ZERO).all() && p.cmplt(Vec2::ONE).all()),
                "{points:?}"
            );
            let mean = points.iter().sum::<Vec2>() / n as f32;
            assert!(
                (mean - 0.5).abs().max_element() < 1e-5,
                "{n} points: mean {mean}"
            );
            assert_eq!(s.jitter(n + 3), s.jitter(3));
        }
        assert!(
            (radical_inverse(3, 2) - 0.75).abs() < 1e-7
                && (radical_inverse(4, 3) - 4.0 / 9.0).abs() < 1e-7
        );
    }

    #[test]
    fn settings_and_names_are_checked() {
        assert!(TaaSettings {
            current_weight: 0.0,
            ..Default::default()
        }
        .validate()
        .is_err());
        assert!(TaaSettings {
            current_weight: f32::NAN,
            ..Default::default()
        }
        .validate()
        .is_err());
        assert!(TaaSettings {
            jitter_points: 4,
            ..Default::default()
        }
        .validate()
        .is_err());
        assert!(TaaSettings::default().validate().is_ok());
        assert_eq!(TaaMode::parse("vp").unwrap().name(), "vp");
        assert_eq!(TaaMode::parse("off").unwrap(), TaaMode::Off);
        assert_eq!(TaaMode::parse("screen").unwrap().name(), "screen");
        let tuned = TaaSettings {
            current_weight: 0.2,
            ..Default::default()
        };
        assert_eq!(
            TaaMode::parse("screen")
                .unwrap()
                .with_settings(tuned)
                .settings(),
            Some(&tuned)
        );
        assert!(TaaMode::parse("on").is_err());
    }
}
