//! `--resampling` and the render profile's `[resampling]` section.

use crate::error::{Error, Result};

/// Which light the resampling passes reuse between samples (`--resampling`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ResamplingMode {
    /// Next-event estimation at every hit, as the tracer does it alone.
    #[default]
    Off,
    /// ReSTIR DI at the primary hit: reservoirs of light samples reused over time and over grid
    /// neighbours (docs/design/resampling.md).
    Di,
    /// ReSTIR DI and ReSTIR GI: the primary hit's bounce (its secondary hit and the radiance
    /// gathered there) resampled too, reconnected between primary hits.
    #[serde(rename = "di+gi")]
    DiGi,
}

impl ResamplingMode {
    /// The names `parse` accepts.
    pub const NAMES: &'static [&'static str] = &["off", "di", "di+gi"];

    pub fn parse(name: &str) -> Result<ResamplingMode> {
        match name {
            "off" => Ok(ResamplingMode::Off),
            "di" => Ok(ResamplingMode::Di),
            "di+gi" => Ok(ResamplingMode::DiGi),
            other => Err(Error::Invalid(format!(
                "resampling '{other}': expected one of {}",
                Self::NAMES.join(", ")
            ))),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ResamplingMode::Off => "off",
            ResamplingMode::Di => "di",
            ResamplingMode::DiGi => "di+gi",
        }
    }

    /// Whether the primary hit's bounce is resampled too (ReSTIR GI).
    pub fn resamples_gi(self) -> bool {
        self == ResamplingMode::DiGi
    }
}

/// The mode and its parameters; `Default` is off with the parameters a profile's
/// `[resampling]` keys default to.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ResamplingSettings {
    pub mode: ResamplingMode,
    /// Light candidates drawn per sample and frame (RIS).
    pub candidates: u32,
    /// Candidates drawn per sample and frame by sampling the BRDF (one ray each: the emissive
    /// triangle it reaches first, if any), weighed against the light candidates by MIS; the
    /// environment's BRDF-sampled share stays the path's own bounce either way.
    pub brdf_candidates: u32,
    /// The previous frame's reservoir counts at most this many times this frame's candidates
    /// (Bitterli et al. 2020 use 20; ReSTIR GI's one traced bounce per frame: this many
    /// frames); 0 turns temporal reuse off.
    pub temporal_cap: f32,
    /// Grid neighbours combined per sample, by ReSTIR DI and GI alike (0: no spatial reuse).
    pub neighbours: u32,
    /// Radius of the neighbours' disc, in grid texels.
    pub radius: f32,
}

impl Default for ResamplingSettings {
    fn default() -> Self {
        ResamplingSettings {
            mode: ResamplingMode::Off,
            candidates: 8,
            brdf_candidates: 1,
            temporal_cap: 20.0,
            neighbours: 3,
            radius: 8.0,
        }
    }
}

/// The ranges `validate` accepts: more candidates or neighbours than these cost more than they
/// gain at one sample per texel; a wider disc leaves the surface the sample stands on.
pub const MAX_CANDIDATES: u32 = 64;
pub const MAX_BRDF_CANDIDATES: u32 = 8;
pub const MAX_TEMPORAL_CAP: f32 = 100.0;
pub const MAX_NEIGHBOURS: u32 = crate::layouts::RESAMPLING_MAX_NEIGHBOURS;
pub const RADIUS_RANGE: (f32, f32) = (1.0, 64.0);

impl ResamplingSettings {
    /// These parameters with `mode`.
    pub fn with_mode(self, mode: ResamplingMode) -> ResamplingSettings {
        ResamplingSettings { mode, ..self }
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(Error::Invalid(format!("resampling: {what}")));
        if !(1..=MAX_CANDIDATES).contains(&self.candidates) {
            return bad(format!(
                "candidates must be in 1..={MAX_CANDIDATES}, got {}",
                self.candidates
            ));
        }
        if self.brdf_candidates > MAX_BRDF_CANDIDATES {
            return bad(format!(
                "brdf_candidates must be in 0..={MAX_BRDF_CANDIDATES}, got {}",
                self.brdf_candidates
            ));
        }
        if !(self.temporal_cap.is_finite() && (0.0..=MAX_TEMPORAL_CAP).contains(&self.temporal_cap))
        {
            return bad(format!(
                "temporal_cap must be in [0, {MAX_TEMPORAL_CAP}], got {}",
                self.temporal_cap
            ));
        }
        if self.neighbours > MAX_NEIGHBOURS {
            return bad(format!(
                "neighbours must be in 0..={MAX_NEIGHBOURS}, got {}",
                self.neighbours
            ));
        }
        let (lo, hi) = RADIUS_RANGE;
        if !(self.radius.is_finite() && (lo..=hi).contains(&self.radius)) {
            return bad(format!(
                "radius must be in [{lo}, {hi}] grid texels, got {}",
                self.radius
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_round_trip_and_bad_names_are_named() {
        for name in ResamplingMode::NAMES {
            assert_eq!(ResamplingMode::parse(name).unwrap().name(), *name);
        }
        let e = ResamplingMode::parse("gi").unwrap_err().to_string();
        assert!(e.contains("'gi'") && e.contains("off, di, di+gi"), "{e}");
    }

    #[test]
    fn parameters_out_of_range_are_refused_by_name() {
        assert!(ResamplingSettings::default().validate().is_ok());
        let cases = [
            (
                ResamplingSettings {
                    candidates: 0,
                    ..Default::default()
                },
                "candidates",
            ),
            (
                ResamplingSettings {
                    brdf_candidates: 9,
                    ..Default::default()
                },
                "brdf_candidates",
            ),
            (
                ResamplingSettings {
                    temporal_cap: -1.0,
                    ..Default::default()
                },
                "temporal_cap",
            ),
            (
                ResamplingSettings {
                    temporal_cap: f32::NAN,
                    ..Default::default()
                },
                "temporal_cap",
            ),
            (
                ResamplingSettings {
                    neighbours: 99,
                    ..Default::default()
                },
                "neighbours",
            ),
            (
                ResamplingSettings {
                    radius: 0.5,
                    ..Default::default()
                },
                "radius",
            ),
        ];
        for (settings, field) in cases {
            let e = settings.validate().unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
    }
}
