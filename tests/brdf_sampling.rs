//! χ² goodness-of-fit of the path tracer's BRDF sampler (`brdf_sample`, shaders/common/brdf.glsl)
//! on the device, Mitsuba's habit: directions drawn through the `passes/brdf_probe` kernel are
//! counted in (θ, φ) cells of the hemisphere around the normal, plus one cell for samples that end
//! the path (below the horizon) and, with a mirror lobe, one for delta samples; each cell's
//! expected count is the sampler's density, written out here from the papers (Lambert's cos θ/π;
//! Heitz 2018's visible-normal GGX, G1(v)·D(h)/(4 n·v); the lobe mix by the Schlick-Fresnel
//! specular probability), integrated over the cell. Pearson's χ² must not reject it at 1 %
//! (Šidák-corrected over the cases). Each sample's returned pdf must equal that density too.

use fovea_renderer::graph::{read_buffer, write_buffer, FrameRecorder};
use fovea_renderer::layouts::BrdfProbePush;
use fovea_renderer::vk::{Buffer, ComputePipeline};
use fovea_test_kit::chi2::{chi2_test, sidak};
use fovea_tests::{assert_clean, gpu};
use glam::{DVec3, UVec4, Vec3, Vec4};
use std::f64::consts::PI;

const SAMPLES: usize = 200_000;
const THETA_CELLS: usize = 10;
const PHI_CELLS: usize = 20;
/// Simpson intervals per cell and axis when integrating the density.
const SIMPSON: usize = 16;
/// Below this roughness brdf.glsl treats the GGX lobe as a mirror.
const MIRROR_ROUGHNESS: f64 = 0.02;

/// One surface and view direction to sample.
#[derive(Clone, Copy, Debug)]
struct Case {
    name: &'static str,
    base_color: [f64; 3],
    metallic: f64,
    roughness: f64,
    specular_factor: f64,
    f0: f64,
    /// The view direction's angle from the normal (degrees).
    view_deg: f64,
    normal: DVec3,
}

const UP: DVec3 = DVec3::Z;

fn cases() -> Vec<Case> {
    let plain = Case {
        name: "",
        base_color: [0.8, 0.6, 0.4],
        metallic: 0.0,
        roughness: 0.5,
        specular_factor: 0.0,
        f0: 0.04,
        view_deg: 30.0,
        normal: UP,
    };
    vec![
        Case {
            name: "Lambert (no specular lobe)",
            ..plain
        },
        Case {
            name: "GGX metal, roughness 0.5, normal view",
            metallic: 1.0,
            view_deg: 0.0,
            ..plain
        },
        Case {
            name: "GGX metal, roughness 0.4, view 60°",
            metallic: 1.0,
            roughness: 0.4,
            view_deg: 60.0,
            ..plain
        },
        Case {
            name: "GGX metal, roughness 0.9, grazing view 80°",
            metallic: 1.0,
            roughness: 0.9,
            view_deg: 80.0,
            ..plain
        },
        Case {
            name: "dielectric: Lambert + GGX by Fresnel, roughness 0.5, view 75°",
            specular_factor: 1.0,
            view_deg: 75.0,
            ..plain
        },
        Case {
            name: "half metal, roughness 0.6, tilted normal",
            metallic: 0.5,
            roughness: 0.6,
            view_deg: 40.0,
            normal: DVec3::new(1.0, -2.0, 3.0).normalize(),
            ..plain
        },
        Case {
            name: "half metal mirror (delta) + Lambert",
            metallic: 0.5,
            roughness: 0.01,
            view_deg: 50.0,
            ..plain
        },
    ]
}

/// An orthonormal frame around the case's normal with φ = 0 toward the view direction, built
/// here (not brdf.glsl's `basis`), so φ is measured the same whatever frame the sampler uses.
struct Frame {
    t: DVec3,
    b: DVec3,
    n: DVec3,
}

impl Case {
    fn frame(&self) -> Frame {
        let n = self.normal;
        let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
        let t = (helper - n * n.dot(helper)).normalize();
        Frame {
            t,
            b: n.cross(t),
            n,
        }
    }

    /// Unit direction toward the viewer.
    fn view(&self) -> DVec3 {
        let f = self.frame();
        let a = self.view_deg.to_radians();
        (f.t * a.sin() + f.n * a.cos()).normalize()
    }

    fn alpha(&self) -> f64 {
        (self.roughness * self.roughness).max(1e-4)
    }

    /// The probability of the specular lobe: the Schlick Fresnel at n·v scaled by the specular
    /// factor for the dielectric part, 1 for the metal part.
    fn specular_probability(&self, n_v: f64) -> f64 {
        let m = (1.0 - n_v).clamp(0.0, 1.0);
        let fresnel = self.f0 + (1.0 - self.f0) * m.powi(5);
        let dielectric = self.specular_factor * fresnel;
        (dielectric + (1.0 - dielectric) * self.metallic).clamp(0.0, 1.0)
    }

    /// The sampler's solid-angle density of the non-delta lobes toward `l`.
    fn pdf(&self, l: DVec3) -> f64 {
        let (n, v) = (self.normal, self.view());
        let (n_l, n_v) = (n.dot(l), n.dot(v));
        if n_l <= 0.0 || n_v <= 0.0 {
            return 0.0;
        }
        let ps = self.specular_probability(n_v);
        let mut pdf = (1.0 - ps) * n_l / PI;
        if self.roughness >= MIRROR_ROUGHNESS {
            let a2 = self.alpha() * self.alpha();
            let n_h = n.dot((v + l).normalize()).max(0.0);
            let d = a2 / (PI * (n_h * n_h * (a2 - 1.0) + 1.0).powi(2));
            let g1 = 2.0 * n_v / (n_v + (a2 + (1.0 - a2) * n_v * n_v).sqrt());
            pdf += ps * g1 * d / (4.0 * n_v);
        }
        pdf
    }

    fn has_delta(&self) -> bool {
        self.roughness < MIRROR_ROUGHNESS
            && self.specular_probability(self.view().dot(self.normal)) > 0.0
    }
}

fn direction(f: &Frame, theta: f64, phi: f64) -> DVec3 {
    (f.t * phi.cos() + f.b * phi.sin()) * theta.sin() + f.n * theta.cos()
}

/// The cell of a hemisphere direction (θ from the normal, φ from the view's azimuth).
fn cell(f: &Frame, l: DVec3) -> Option<usize> {
    let z = l.dot(f.n);
    if z <= 0.0 {
        return None;
    }
    let theta = z.min(1.0).acos();
    let phi = l.dot(f.b).atan2(l.dot(f.t)).rem_euclid(2.0 * PI);
    let i = ((theta / (0.5 * PI) * THETA_CELLS as f64) as usize).min(THETA_CELLS - 1);
    let j = ((phi / (2.0 * PI) * PHI_CELLS as f64) as usize).min(PHI_CELLS - 1);
    Some(i * PHI_CELLS + j)
}

/// ∫∫ pdf sin θ dθ dφ over every cell (composite Simpson), row-major like `cell`.
fn integrated(case: &Case) -> Vec<f64> {
    let f = case.frame();
    let (dt, dp) = (0.5 * PI / THETA_CELLS as f64, 2.0 * PI / PHI_CELLS as f64);
    let weight = |k: usize| match k {
        0 => 1.0,
        k if k == SIMPSON => 1.0,
        k if k % 2 == 1 => 4.0,
        _ => 2.0,
    };
    let mut cells = vec![0.0; THETA_CELLS * PHI_CELLS];
    for i in 0..THETA_CELLS {
        for j in 0..PHI_CELLS {
            let (ht, hp) = (dt / SIMPSON as f64, dp / SIMPSON as f64);
            let mut sum = 0.0;
            for a in 0..=SIMPSON {
                let theta = i as f64 * dt + a as f64 * ht;
                for b in 0..=SIMPSON {
                    let phi = j as f64 * dp + b as f64 * hp;
                    let l = direction(&f, theta, phi);
                    sum += weight(a) * weight(b) * case.pdf(l) * theta.sin();
                }
            }
            cells[i * PHI_CELLS + j] = sum * ht * hp / 9.0;
        }
    }
    cells
}

/// SplitMix64 uniforms in [0, 1) (f32), seeded per case.
fn randoms(seed: u64, n: usize) -> Vec<Vec4> {
    let mut s = seed;
    let mut next = move || {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..n)
        .map(|_| Vec4::new(next(), next(), next(), 0.0))
        .collect()
}

/// Samples of every case through `passes/brdf_probe`: (direction, pdf; 0 ended, −1 delta).
fn draw(cases: &[Case]) -> Vec<Vec<Vec4>> {
    let ctx = gpu();
    let pipeline = ComputePipeline::new(
        &ctx,
        "passes/brdf_probe",
        std::mem::size_of::<BrdfProbePush>() as u32,
    )
    .unwrap();
    let storage = ash::vk::BufferUsageFlags::STORAGE_BUFFER;
    let mut out = Vec::new();
    for (k, case) in cases.iter().enumerate() {
        let input =
            Buffer::with_data(&ctx, "randoms", &randoms(k as u64 + 1, SAMPLES), storage).unwrap();
        let directions = Buffer::new(
            &ctx,
            "directions",
            (SAMPLES * 16) as u64,
            storage,
            gpu_allocator::MemoryLocation::GpuToCpu,
        )
        .unwrap();
        let f32s = |v: DVec3| v.as_vec3();
        let push = BrdfProbePush {
            base_color_metallic: Vec3::from_array(case.base_color.map(|c| c as f32))
                .extend(case.metallic as f32),
            f0_specular: Vec4::new(
                case.f0 as f32,
                case.f0 as f32,
                case.f0 as f32,
                case.specular_factor as f32,
            ),
            view_roughness: f32s(case.view()).extend(case.roughness as f32),
            normal: f32s(case.normal).extend(0.0),
            config: UVec4::new(SAMPLES as u32, 0, 0, 0),
        };
        let mut rec = FrameRecorder::new(&ctx, 2).unwrap();
        rec.begin().unwrap();
        rec.dispatch(
            "brdf_probe",
            &pipeline,
            &[
                read_buffer("randoms", &input),
                write_buffer("directions", &directions),
            ],
            bytemuck::bytes_of(&push),
            [SAMPLES as u32, 1, 1],
        )
        .unwrap();
        rec.submit_and_wait().unwrap();
        out.push(directions.read().unwrap());
    }
    assert_clean(&ctx);
    out
}

#[test]
fn brdf_sampler_follows_its_density() {
    let cases = cases();
    let samples = draw(&cases);
    let level = sidak(0.01, cases.len());
    let mut failures = Vec::new();
    for (case, drawn) in cases.iter().zip(&samples) {
        let f = case.frame();
        let n = SAMPLES as f64;
        // Cells of the hemisphere, then the ended samples, then (mirror) the delta ones.
        let mut expected: Vec<f64> = integrated(case).iter().map(|p| p * n).collect();
        let hemisphere: f64 = expected.iter().sum::<f64>() / n;
        let ps = case.specular_probability(case.view().dot(case.normal));
        let delta = if case.has_delta() { ps } else { 0.0 };
        let mut observed = vec![0.0; expected.len() + 2];
        let (mut worst_pdf, mut worst_mirror, mut below) = (0f64, 0f64, 0);
        for s in drawn {
            let l = s.truncate().as_dvec3();
            match s.w {
                w if w < 0.0 => {
                    observed[expected.len() + 1] += 1.0;
                    let mirror = 2.0 * case.view().dot(case.normal) * case.normal - case.view();
                    worst_mirror = worst_mirror.max((l - mirror).length());
                }
                0.0 => observed[expected.len()] += 1.0,
                w => match cell(&f, l) {
                    Some(c) => {
                        observed[c] += 1.0;
                        let want = case.pdf(l.normalize());
                        worst_pdf = worst_pdf.max((w as f64 - want).abs() / want);
                    }
                    // A direction kept below the horizon: impossible under the density.
                    None => below += 1,
                },
            }
        }
        // The non-delta lobes lose what they reflect below the horizon; the delta lobe takes its
        // share before them.
        let kept = hemisphere;
        expected.push(n * ((1.0 - delta) - kept).max(0.0));
        expected.push(n * delta);
        let outcome = chi2_test(&observed, &expected, level);
        println!(
            "{}: p_s {ps:.3}, below the horizon {:.4}, worst pdf error {worst_pdf:.1e}, {}",
            case.name,
            observed[expected.len() - 2] / n,
            match &outcome {
                Ok(o) => o.to_string(),
                Err(e) => e.clone(),
            }
        );
        if let Err(e) = outcome {
            failures.push(format!("{}: {e}", case.name));
        }
        if worst_pdf > 2e-3 {
            failures.push(format!(
                "{}: returned pdf off the density by {worst_pdf:.1e} (relative)",
                case.name
            ));
        }
        if below > 0 {
            failures.push(format!(
                "{}: {below} directions below the horizon kept",
                case.name
            ));
        }
        if worst_mirror > 1e-5 {
            failures.push(format!(
                "{}: a delta sample {worst_mirror:.1e} off the mirror direction",
                case.name
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
