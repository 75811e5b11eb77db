//! The sampling methods of `--method`, one registry entry each: its name, what it needs of the
//! screen, whether its way back ends in the foveated blur, what report.json records of its
//! parameters, and how its space is built for one eye. A new method is one entry here (and its
//! space in the renderer); render, view, xr, quality and their reports read it from here.

use crate::render_profile::RenderProfile;
use anyhow::{anyhow, Context, Result};
use fovea_hal::HmdDescription;
use fovea_renderer::sampling::{
    BlockShape, Cartesian, Eccentricity, FalloffShape, FixedFoveation, FovTangents, LinearFalloff,
    PixelBlocks, RandomAcuity, SamplingSpace, UniformBudget, VisualPolar, VisualPolarParams,
    VpLayout, VrsTiles, FALLOFF_BUDGET_OF_VP,
};
use glam::{UVec2, Vec2};

/// What a method needs of the screen, checked before the device opens (`setup::check_space`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScreenNeeds {
    /// Any size from 1×1.
    Any,
    /// A Visual-Polar grid (the method is VP or is sized by VP's sample count or axis).
    VisualPolarGrid,
    /// A log-polar buffer of at least the minimum grid.
    LogPolarBuffer,
    /// Room for a gaze disc and a log-polar buffer.
    CompositeDisc,
}

/// Which Visual-Polar variant a VP method is: the profile's, or a layout / axis it forces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VpVariant {
    Profile,
    Paper,
    ScreenClipped,
    ScreenAware,
    Headset,
}

/// The parameter section report.json records for a method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReportSection {
    None,
    VisualPolar(VpVariant),
    LogPolar,
    Composite,
}

/// What a space is built from for one eye.
pub struct SpaceInputs<'a> {
    pub profile: &'a RenderProfile,
    pub hmd: &'a HmdDescription,
    /// The eye's FOV as tangents (the headset axis and composite's viewing distance).
    pub fov: FovTangents,
    /// The profile's Visual-Polar parameters for this eye.
    pub vp: VisualPolarParams,
    pub screen: UVec2,
}

impl SpaceInputs<'_> {
    /// Spaces are built around the screen centre: every frame, the first included, re-centres
    /// them on its gaze.
    fn centre(&self) -> Vec2 {
        self.screen.as_vec2() * 0.5
    }

    fn visual_polar(
        &self,
        params: VisualPolarParams,
        what: &str,
    ) -> Result<Box<dyn SamplingSpace>> {
        Ok(Box::new(
            VisualPolar::new(self.screen, self.centre(), params)
                .with_context(|| what.to_string())?,
        ))
    }
}

/// One `--method`.
pub struct Method {
    pub name: &'static str,
    pub screen: ScreenNeeds,
    /// Its way back ends in the profile's foveated blur (report.json `blur_sigma_at_30`).
    pub blurs: bool,
    pub report: ReportSection,
    build: fn(&SpaceInputs) -> Result<Box<dyn SamplingSpace>>,
}

impl Method {
    /// This method's sampling space for one eye.
    pub fn space(&self, inputs: &SpaceInputs) -> Result<Box<dyn SamplingSpace>> {
        (self.build)(inputs)
    }
}

/// Every method, in the order `--methods all` and the viewer's `m` key visit them.
pub const METHODS: &[Method] = &[
    Method {
        name: "vp",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: true,
        report: ReportSection::VisualPolar(VpVariant::Profile),
        build: |i| i.visual_polar(i.vp, "Visual-Polar space"),
    },
    Method {
        name: "cartesian",
        screen: ScreenNeeds::Any,
        blurs: false,
        report: ReportSection::None,
        build: |i| Ok(Box::new(Cartesian::new(i.screen))),
    },
    // Visual-Polar's sample count for this eye and profile, spent on a regular grid.
    Method {
        name: "uniform-budget",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: false,
        report: ReportSection::None,
        build: |i| {
            let vp = VisualPolar::new(i.screen, i.centre(), i.vp)
                .context("Visual-Polar space (the uniform budget's count)")?;
            Ok(Box::new(UniformBudget::with_samples(
                i.screen,
                vp.sample_count(),
            )?))
        },
    },
    // Meng's kernel log-polar buffer: the polar space with the log-polar radial law.
    Method {
        name: "log-polar",
        screen: ScreenNeeds::LogPolarBuffer,
        blurs: true,
        report: ReportSection::LogPolar,
        build: |i| i.visual_polar(i.profile.log_polar_space(), "log-polar space"),
    },
    // Weier et al.'s falloff on VP's eccentricity axis with 1.5× its samples (Koskela 2019).
    Method {
        name: "linear-falloff",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: true,
        report: ReportSection::None,
        build: |i| {
            Ok(Box::new(
                LinearFalloff::new(
                    i.screen,
                    i.vp,
                    FalloffShape::default(),
                    FALLOFF_BUDGET_OF_VP,
                )
                .context("linear falloff")?,
            ))
        },
    },
    // VP's samples at random positions drawn from its density (Koskela et al. 2018).
    Method {
        name: "random-acuity",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: true,
        report: ReportSection::None,
        build: |i| {
            // Drawn from the paper layout's density, whatever the profile's layout.
            let paper = VisualPolarParams {
                layout: VpLayout::Paper,
                ..i.vp
            };
            Ok(Box::new(
                RandomAcuity::new(i.screen, i.centre(), paper).context("random acuity")?,
            ))
        },
    },
    // Mohanto et al.'s pixel / 2×2 / 4×4 regions on VP's eccentricity axis, 4 / 2 / 1 samples.
    Method {
        name: "pixel-blocks",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: false,
        report: ReportSection::None,
        build: |i| {
            Ok(Box::new(
                PixelBlocks::new(i.screen, i.vp, BlockShape::default()).context("pixel blocks")?,
            ))
        },
    },
    // Andersson & Hansson's gaze disc + log-polar; the eye's distance from its FOV.
    Method {
        name: "composite",
        screen: ScreenNeeds::CompositeDisc,
        blurs: true,
        report: ReportSection::Composite,
        build: |i| {
            let viewing_distance = i.screen.x as f32 / (i.fov.right + i.fov.left).max(1e-3);
            i.visual_polar(
                i.profile.composite_space(viewing_distance),
                "composite space",
            )
        },
    },
    // Visual-Polar's variants as methods of their own (the method table's rows).
    Method {
        name: "vp-paper",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: true,
        report: ReportSection::VisualPolar(VpVariant::Paper),
        build: |i| {
            i.visual_polar(
                VisualPolarParams {
                    layout: VpLayout::Paper,
                    ..i.vp
                },
                "Visual-Polar space, the paper's layout",
            )
        },
    },
    Method {
        name: "vp-screen-clipped",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: true,
        report: ReportSection::VisualPolar(VpVariant::ScreenClipped),
        build: |i| {
            i.visual_polar(
                VisualPolarParams {
                    layout: VpLayout::ScreenClipped,
                    ..i.vp
                },
                "Visual-Polar space, screen-clipped layout",
            )
        },
    },
    Method {
        name: "vp-screen-aware",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: true,
        report: ReportSection::VisualPolar(VpVariant::ScreenAware),
        build: |i| {
            i.visual_polar(
                VisualPolarParams {
                    layout: VpLayout::ScreenAware,
                    ..i.vp
                },
                "Visual-Polar space, screen-aware axis",
            )
        },
    },
    Method {
        name: "vp-headset",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: true,
        report: ReportSection::VisualPolar(VpVariant::Headset),
        build: |i| {
            let params = VisualPolarParams {
                eccentricity: Eccentricity::Headset(i.fov),
                layout: VpLayout::Paper,
                ..i.vp
            };
            i.visual_polar(
                params,
                &format!("Visual-Polar space, headset axis of {}", i.hmd.id),
            )
        },
    },
    // Visual-Polar held on the lens centre (fixed foveated rendering): what eye tracking buys.
    Method {
        name: "fixed-foveation",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: true,
        report: ReportSection::VisualPolar(VpVariant::Profile),
        build: |i| {
            Ok(Box::new(
                FixedFoveation::new(i.screen, FixedFoveation::lens_centre(i.screen, i.fov), i.vp)
                    .context("fixed foveation")?,
            ))
        },
    },
    // Variable-rate-shading foveation: 16×16 tiles at 1×1, 2×2 or 4×4, never sparser than VP.
    Method {
        name: "vrs-tiles",
        screen: ScreenNeeds::VisualPolarGrid,
        blurs: true,
        report: ReportSection::None,
        build: |i| {
            // Tiles follow the paper layout's density, whatever the profile's layout.
            let paper = VisualPolarParams {
                layout: VpLayout::Paper,
                ..i.vp
            };
            Ok(Box::new(
                VrsTiles::new(i.screen, i.centre(), paper).context("vrs tiles")?,
            ))
        },
    },
];

/// The method called `name`, or an error naming the ones there are.
pub fn method(name: &str) -> Result<&'static Method> {
    METHODS
        .iter()
        .find(|m| m.name == name)
        .ok_or_else(|| anyhow!("--method {name}: expected one of {}", names().join(", ")))
}

/// Every method's name, in registry order.
pub fn names() -> Vec<&'static str> {
    METHODS.iter().map(|m| m.name).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_unknown_ones_are_named() {
        let mut sorted = names();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), METHODS.len());
        let err = method("foveated").err().unwrap().to_string();
        assert!(
            err.contains("--method foveated") && err.contains("vp-screen-clipped"),
            "{err}"
        );
    }
}
