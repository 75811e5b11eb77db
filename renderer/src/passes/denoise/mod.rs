//! Denoisers (design: shared/design/denoisers.md). They run in the sampling grid between the tracer and
//! the way back to the screen — texel = sample, in Cartesian and Visual-Polar space alike — and
//! return re-modulated radiance of the grid's size. A denoiser is one module here (SVGF, A-SVGF,
//! BMFR; TAA, which runs after them, is `passes::taa`) whose parameters implement
//! `DenoiserParams` and whose per-eye state implements `Denoiser`, its shaders (one pass = one
//! `Pass` + one shader, a variant per sampling space, `shaders/passes/denoise/`, + one
//! push-constant struct in `layouts.glsl`; the grid addressing they share is
//! `shaders/denoise/grid.glsl`), and one entry in `registry!` below: the `--denoiser` names, the
//! viewer's key cycle and the render profile's sections all come from it.

pub mod asvgf;
pub mod bmfr;
mod denoiser;
pub mod modulate;
pub mod svgf;

pub use denoiser::{Denoiser, DenoiserParams, OtherParams};

use crate::error::{Error, Result};
use crate::vk::Context;
use denoiser::ErasedParams;
use glam::UVec2;
use std::any::Any;
use std::sync::Arc;

/// Defines `DenoiserSettings` (a variant per registered denoiser, holding its parameters) and
/// what is listed over the registry: the names, the defaults, the profile sections.
macro_rules! registry {
    ($($variant:ident($params:ty)),+ $(,)?) => {
        /// Which denoiser runs after the tracer (`fovea render --denoiser`), with its parameters.
        #[derive(Clone, Copy, Debug, PartialEq, Default)]
        pub enum DenoiserSettings {
            /// The tracer's colour goes to the screen as is.
            #[default]
            None,
            $($variant($params),)+
        }

        $(impl From<$params> for DenoiserSettings {
            fn from(params: $params) -> Self {
                DenoiserSettings::$variant(params)
            }
        })+

        impl DenoiserSettings {
            /// The names `parse` accepts: `none`, then the registry's, in its order.
            pub const NAMES: &'static [&'static str] =
                &["none", $(<$params as DenoiserParams>::NAME),+];

            fn params(&self) -> Option<&dyn ErasedParams> {
                match self {
                    DenoiserSettings::None => None,
                    $(DenoiserSettings::$variant(p) => Some(p),)+
                }
            }

            fn params_mut(&mut self) -> Option<&mut dyn ErasedParams> {
                match self {
                    DenoiserSettings::None => None,
                    $(DenoiserSettings::$variant(p) => Some(p),)+
                }
            }

            /// The registered denoiser whose render-profile section is `section`, its parameters
            /// read from `de` onto its defaults; `None` when no denoiser has that section.
            pub fn deserialize_section<'de, D: serde::Deserializer<'de>>(
                section: &str,
                de: D,
            ) -> std::result::Result<Option<DenoiserSettings>, D::Error> {
                $(if section == <$params as DenoiserParams>::NAME {
                    let params = <$params as serde::Deserialize>::deserialize(de)?;
                    return Ok(Some(params.into()));
                })+
                Ok(None)
            }
        }

        impl Default for DenoiserProfile {
            fn default() -> Self {
                DenoiserProfile {
                    settings: vec![$(<$params>::default().into()),+],
                }
            }
        }
    };
}

// The registry: one `DenoiserSettings` variant per denoiser and its parameters type, in the
// order `--denoiser`, the viewer's cycle and the profile list them.
registry! {
    Svgf(svgf::SvgfSettings),
    Asvgf(asvgf::AsvgfSettings),
    Bmfr(bmfr::BmfrSettings),
}

impl DenoiserSettings {
    /// A denoiser by name, with its defaults.
    pub fn parse(name: &str) -> Result<DenoiserSettings> {
        DenoiserProfile::default().get(name)
    }

    pub fn name(&self) -> &'static str {
        self.params().map_or("none", |p| p.name())
    }

    /// Whether the tracer must re-shade gradient samples (its `*_gradients` variant) and keep
    /// the visibility they are projected from.
    pub fn needs_gradients(&self) -> bool {
        self.params().is_some_and(|p| p.needs_gradients())
    }

    pub fn validate(&self) -> Result<()> {
        self.params().map_or(Ok(()), |p| p.validate())
    }

    /// The denoiser with its per-eye state for a grid of `grid` texels (`None` for none);
    /// `variant` is the sampling space's kernel variant (`SamplingSpace::shader_variant`).
    pub fn build(
        &self,
        ctx: &Arc<Context>,
        grid: UVec2,
        variant: &str,
    ) -> Result<Option<Box<dyn Denoiser>>> {
        self.params()
            .map(|p| p.build(ctx, grid, variant))
            .transpose()
    }
}

/// Every registered denoiser's parameters, in the registry's order: its defaults, then what a
/// render profile's sections give (`set`, `complete`).
#[derive(Clone, Debug, PartialEq)]
pub struct DenoiserProfile {
    settings: Vec<DenoiserSettings>,
}

impl DenoiserProfile {
    /// Replaces one denoiser's parameters (a profile section, `deserialize_section`).
    pub fn set(&mut self, settings: DenoiserSettings) {
        if let Some(slot) = self
            .settings
            .iter_mut()
            .find(|s| s.name() == settings.name())
        {
            *slot = settings;
        }
    }

    /// Completes each denoiser's parameters from the others' (`DenoiserParams::complete`), once
    /// every section is set.
    pub fn complete(&mut self) {
        let others = self.clone();
        for settings in &mut self.settings {
            if let Some(p) = settings.params_mut() {
                p.complete(&others);
            }
        }
    }

    /// Each denoiser's parameters, in the registry's order.
    pub fn iter(&self) -> impl Iterator<Item = &DenoiserSettings> {
        self.settings.iter()
    }

    /// Denoiser `name` (`none` or a registered one) with these parameters.
    pub fn get(&self, name: &str) -> Result<DenoiserSettings> {
        if name == "none" {
            return Ok(DenoiserSettings::None);
        }
        self.settings
            .iter()
            .find(|s| s.name() == name)
            .copied()
            .ok_or_else(|| {
                Error::Invalid(format!(
                    "denoiser '{name}': expected one of {}",
                    DenoiserSettings::NAMES.join(", ")
                ))
            })
    }
}

impl OtherParams for DenoiserProfile {
    fn params(&self, name: &str) -> Option<&dyn Any> {
        self.settings
            .iter()
            .find(|s| s.name() == name)
            .and_then(|s| s.params())
            .map(|p| p.as_any())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::de::value::{Error as ValueError, MapDeserializer};

    #[test]
    fn every_registered_name_parses_to_itself_and_unknown_names_list_them() {
        assert_eq!(DenoiserSettings::NAMES, ["none", "svgf", "asvgf", "bmfr"]);
        for &name in DenoiserSettings::NAMES {
            assert_eq!(DenoiserSettings::parse(name).unwrap().name(), name);
        }
        let err = DenoiserSettings::parse("nlm").unwrap_err().to_string();
        assert!(
            err.contains("nlm") && err.contains("none, svgf, asvgf, bmfr"),
            "{err}"
        );
        let gradients: Vec<_> = DenoiserSettings::NAMES
            .iter()
            .filter(|n| DenoiserSettings::parse(n).unwrap().needs_gradients())
            .collect();
        assert_eq!(gradients, [&"asvgf"]);
    }

    /// A section sets its keys on the defaults, and A-SVGF's SVGF stages take `[svgf]`'s.
    #[test]
    fn profile_sections_read_onto_the_defaults_and_complete_each_other() {
        let section = |name: &str, keys: Vec<(&'static str, f32)>| {
            let de = MapDeserializer::<_, ValueError>::new(keys.into_iter());
            DenoiserSettings::deserialize_section(name, de).unwrap()
        };
        let svgf = section("svgf", vec![("alpha_color", 0.5)]).unwrap();
        let DenoiserSettings::Svgf(s) = svgf else {
            panic!("{svgf:?}")
        };
        assert_eq!(s.alpha_color, 0.5);
        assert_eq!(s.max_history, svgf::SvgfSettings::default().max_history);
        assert_eq!(section("nlm", vec![]), None);
        let mut profile = DenoiserProfile::default();
        profile.set(svgf);
        profile.complete();
        let DenoiserSettings::Asvgf(a) = profile.get("asvgf").unwrap() else {
            panic!("asvgf is registered")
        };
        assert_eq!(a.svgf, s);
        assert_eq!(profile.get("none").unwrap(), DenoiserSettings::None);
    }
}
