use fovea_hal::sim::motion::{direction_from_angles, tangent_basis};
use fovea_hal::sim::{EyePhase, ScriptMotion, ScriptStep, SimTick};
use fovea_hal::{GazeSource, HmdDescription, SimConfig, SimulatedFove};
use glam::{DVec3, Vec3};
use std::path::Path;

fn angle_deg(a: Vec3, b: Vec3) -> f64 {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

fn sim(cfg: SimConfig) -> SimulatedFove {
    SimulatedFove::new(HmdDescription::fove0(), cfg).unwrap()
}

fn run(s: &mut SimulatedFove, seconds: f64) -> Vec<SimTick> {
    let n = (seconds * s.describe().tracker.rate_hz as f64) as usize;
    (0..n).map(|_| s.step()).collect()
}

/// Maximal runs of ticks whose phase satisfies `pred`: (first index, end index exclusive).
fn runs(ticks: &[SimTick], pred: impl Fn(EyePhase) -> bool) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, t) in ticks.iter().enumerate() {
        match (pred(t.phase), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    out
}

#[test]
fn fixation_durations_have_the_configured_mean() {
    let cfg = SimConfig::seeded(7);
    let mut s = sim(cfg.clone());
    let ticks = run(&mut s, 1200.0);
    let fixations = runs(&ticks, |p| {
        matches!(p, EyePhase::Fixation | EyePhase::Microsaccade)
    });
    let period_ms = 1000.0 / 120.0;
    // Drop the first and last run: they are cut by the start and end of the recording.
    let durations: Vec<f64> = fixations[1..fixations.len() - 1]
        .iter()
        .map(|(a, b)| (b - a) as f64 * period_ms)
        .collect();
    let mean = durations.iter().sum::<f64>() / durations.len() as f64;
    assert!(durations.len() > 2000, "{}", durations.len());
    assert!((250.0..=300.0).contains(&mean), "mean fixation {mean} ms");
    assert!(
        (mean - cfg.fixation_mean_ms).abs() < 0.05 * cfg.fixation_mean_ms,
        "mean fixation {mean} ms"
    );
    // Right-skewed: the median lies below the mean.
    let mut sorted = durations.clone();
    sorted.sort_by(f64::total_cmp);
    assert!(sorted[sorted.len() / 2] < mean);
}

#[test]
fn saccade_peak_velocity_follows_the_main_sequence() {
    let cfg = SimConfig {
        rate_hz: Some(1000.0),
        precision_deg: Some(0.0),
        accuracy_deg: Some(0.0),
        blink_rate_per_min: 0.0,
        ..SimConfig::seeded(3)
    };
    let mut s = sim(cfg.clone());
    let ticks = run(&mut s, 120.0);
    let dt = 0.001;
    let mut checked = 0;
    for (a, b) in runs(&ticks, |p| p == EyePhase::Saccade) {
        if a == 0 || b >= ticks.len() {
            continue;
        }
        let amplitude = angle_deg(ticks[a - 1].truth, ticks[b].truth);
        if amplitude < 0.5 {
            continue;
        }
        let peak = (a - 1..b)
            .map(|i| angle_deg(ticks[i].truth, ticks[i + 1].truth) / dt)
            .fold(0.0, f64::max);
        let expected = cfg.main_sequence_peak_velocity(amplitude);
        assert!(
            (peak / expected - 1.0).abs() < 0.15,
            "A={amplitude:.2}° peak {peak:.1} vs {expected:.1} °/s"
        );
        checked += 1;
    }
    assert!(checked > 200, "{checked} saccades checked");
}

#[test]
fn blink_rate_is_as_configured_and_samples_are_invalid_exactly_during_blinks() {
    let cfg = SimConfig::seeded(11);
    let mut s = sim(cfg.clone());
    let ticks = run(&mut s, 1800.0);
    let mut blinks = 0;
    for (i, t) in ticks.iter().enumerate() {
        assert_eq!(t.sample.valid, !t.blinking, "tick {i}");
        assert_eq!(t.sample.tracked, !t.blinking, "tick {i}");
        if i > 0 && t.blinking && !ticks[i - 1].blinking {
            blinks += 1;
        }
    }
    let per_min = blinks as f64 / 30.0;
    assert!(
        (per_min / cfg.blink_rate_per_min - 1.0).abs() < 0.1,
        "{per_min} blinks/min"
    );
}

/// Angular offset (degrees, right/up) of `measured` from `truth` in truth's tangent plane.
fn offset_deg(truth: Vec3, measured: Vec3) -> (f64, f64) {
    let (d, m) = (truth.as_dvec3(), measured.as_dvec3());
    let (right, up): (DVec3, DVec3) = tangent_basis(d);
    let fwd = m.dot(d);
    (
        (m.dot(right) / fwd).atan().to_degrees(),
        (m.dot(up) / fwd).atan().to_degrees(),
    )
}

#[test]
fn precision_noise_has_the_configured_sigma() {
    let cfg = SimConfig {
        accuracy_deg: Some(0.0),
        precision_deg: Some(0.3),
        ..SimConfig::seeded(5)
    };
    let mut s = sim(cfg);
    let ticks = run(&mut s, 300.0);
    let errs: Vec<(f64, f64)> = ticks
        .iter()
        .filter(|t| t.sample.valid)
        .map(|t| offset_deg(t.truth, t.sample.gaze.direction))
        .collect();
    for axis in 0..2 {
        let v: Vec<f64> = errs
            .iter()
            .map(|e| if axis == 0 { e.0 } else { e.1 })
            .collect();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
        assert!((sd / 0.3 - 1.0).abs() < 0.05, "axis {axis}: sd {sd}");
        assert!(mean.abs() < 0.01, "axis {axis}: mean {mean}");
    }
}

#[test]
fn accuracy_bias_varies_slowly_with_the_configured_mean_error() {
    let cfg = SimConfig {
        precision_deg: Some(0.0),
        ..SimConfig::seeded(9)
    };
    let mut s = sim(cfg);
    let ticks = run(&mut s, 3600.0);
    let mean_err = ticks
        .iter()
        .map(|t| t.bias_deg.length() as f64)
        .sum::<f64>()
        / ticks.len() as f64;
    assert!((mean_err / 1.15 - 1.0).abs() < 0.2, "mean bias {mean_err}°");
    // Slow: consecutive ticks differ by far less than the bias itself.
    let max_step = ticks
        .windows(2)
        .map(|w| (w[1].bias_deg - w[0].bias_deg).length())
        .fold(0.0f32, f32::max);
    assert!(max_step < 0.1, "{max_step}");
    // And the measured sample really carries it.
    let t = ticks.iter().find(|t| t.sample.valid).unwrap();
    let (x, y) = offset_deg(t.truth, t.sample.gaze.direction);
    assert!((x - t.bias_deg.x as f64).abs() < 1e-3 && (y - t.bias_deg.y as f64).abs() < 1e-3);
}

#[test]
fn same_seed_gives_bit_identical_samples_whatever_the_query_pattern() {
    let mut a = SimulatedFove::fove0(42);
    let mut b = SimulatedFove::fove0(42);
    let mut c = SimulatedFove::fove0(43);
    let stepped: Vec<_> = (0..2000).map(|_| a.step().sample).collect();
    let mut differs = false;
    for frame in 0..1000i64 {
        let t = frame * 14_285_714; // 70 Hz frames
        let s = b.sample_at(t);
        let k = s.sequence as usize;
        if k < stepped.len() {
            assert!(s.bit_eq(&stepped[k]), "frame {frame}");
        }
        differs |= !c.sample_at(t).bit_eq(&s);
    }
    assert!(differs, "different seeds must give different gaze");
}

#[test]
fn renderer_sees_samples_one_tracker_latency_old() {
    let mut s = SimulatedFove::fove0(1);
    let latency = 20_000_000;
    let period = s.describe().tracker_period_ns();
    for frame in 10..200i64 {
        let t = frame * 14_285_714;
        s.begin_frame(t).unwrap();
        let g = s.sample_at(t);
        assert!(
            g.time <= t - latency && g.time > t - latency - period - 1,
            "t={t} sample {}",
            g.time
        );
        assert_eq!(g.time_kind, fovea_hal::SampleTimeKind::Measured);
        assert!(s.latest().bit_eq(&g));
    }
    // Asking for an older time returns the older measurement again (history), not a newer one.
    let old = s.sample_at(100 * 14_285_714);
    assert!(old.time <= 100 * 14_285_714 - latency);
}

fn quiet_script(script: Vec<ScriptStep>) -> SimConfig {
    SimConfig {
        script,
        saccade_latency_ms: 150.0,
        microsaccade_rate_hz: 0.0,
        drift_sd_deg: 0.0,
        blink_rate_per_min: 0.0,
        precision_deg: Some(0.0),
        accuracy_deg: Some(0.0),
        ..SimConfig::default()
    }
}

#[test]
fn scripted_jump_produces_a_saccade_after_the_reaction_time() {
    let step = |t, az, el| ScriptStep {
        time_ms: t,
        azimuth_deg: az,
        elevation_deg: el,
        motion: ScriptMotion::Jump,
    };
    let mut s = sim(quiet_script(vec![
        step(100.0, 10.0, 0.0),
        step(1000.0, -5.0, 5.0),
    ]));
    let ticks = run(&mut s, 2.0);
    let at = |ms: f64| &ticks[(ms * 0.12) as usize];
    assert!(
        angle_deg(at(240.0).truth, Vec3::NEG_Z) < 1e-3,
        "still fixating before 100+150 ms"
    );
    assert_eq!(at(300.0).phase, EyePhase::Saccade);
    let target = direction_from_angles(10.0, 0.0).as_vec3();
    assert!(angle_deg(at(900.0).truth, target) < 1e-3);
    assert_eq!(at(900.0).phase, EyePhase::Fixation);
    let second = direction_from_angles(-5.0, 5.0).as_vec3();
    assert!(angle_deg(at(1900.0).truth, second) < 1e-3);
}

#[test]
fn scripted_pursuit_follows_a_moving_target_with_catch_up_saccades() {
    let jump = ScriptStep {
        time_ms: 0.0,
        azimuth_deg: -10.0,
        elevation_deg: 0.0,
        motion: ScriptMotion::Jump,
    };
    let glide = ScriptStep {
        time_ms: 2000.0,
        azimuth_deg: 10.0,
        elevation_deg: 0.0,
        motion: ScriptMotion::Pursue,
    };
    let mut s = sim(quiet_script(vec![jump, glide]));
    let ticks = run(&mut s, 3.0);
    let pursuit = ticks
        .iter()
        .filter(|t| t.phase == EyePhase::Pursuit)
        .count();
    assert!(pursuit > 120, "{pursuit} pursuit ticks");
    // Eye speed during pursuit ≈ gain × 10°/s.
    let speeds: Vec<f64> = ticks
        .windows(2)
        .filter(|w| w[0].phase == EyePhase::Pursuit && w[1].phase == EyePhase::Pursuit)
        .map(|w| angle_deg(w[0].truth, w[1].truth) * 120.0)
        .collect();
    let mean = speeds.iter().sum::<f64>() / speeds.len() as f64;
    assert!((mean - 9.0).abs() < 0.5, "pursuit speed {mean}°/s");
    // It ends on the final target.
    assert!(
        angle_deg(
            ticks.last().unwrap().truth,
            direction_from_angles(10.0, 0.0).as_vec3()
        ) < 0.6
    );
}

#[test]
fn random_pursuit_episodes_happen_when_asked() {
    let cfg = SimConfig {
        pursuit_probability: 0.5,
        ..SimConfig::seeded(2)
    };
    let ticks = run(&mut sim(cfg), 60.0);
    assert!(
        ticks
            .iter()
            .filter(|t| t.phase == EyePhase::Pursuit)
            .count()
            > 1000
    );
    assert!(ticks
        .iter()
        .all(|t| t.truth.is_finite() && (t.truth.length() - 1.0).abs() < 1e-4));
}

#[test]
fn microsaccades_and_drift_stay_small() {
    let cfg = SimConfig {
        blink_rate_per_min: 0.0,
        ..SimConfig::seeded(4)
    };
    let ticks = run(&mut sim(cfg), 600.0);
    let micros = runs(&ticks, |p| p == EyePhase::Microsaccade).len() as f64 / 600.0;
    // Fixations fill most of the time; microsaccades run at ~1.5/s within them.
    assert!((0.7..2.0).contains(&micros), "{micros} microsaccades/s");
}

#[test]
fn simulator_toml_parses_and_rejects_bad_input() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../config/gaze/sim_example.toml"
    );
    let cfg = SimConfig::load(Path::new(path)).unwrap();
    assert!(!cfg.script.is_empty());
    sim(cfg);
    let e = SimConfig::parse("fixation_mean = 3", Path::new("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("s.toml") && e.contains("fixation_mean"), "{e}");
    let e = SimConfig::parse("blink_duration_ms = [400, 100]", Path::new("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("blink_duration_ms"), "{e}");
    let e = SimConfig::parse("rate_hz = -1.0", Path::new("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("rate_hz"), "{e}");
    let bad_script = "[[script]]\ntime_ms = 5\nazimuth_deg = 0\nelevation_deg = 0\n[[script]]\ntime_ms = 5\nazimuth_deg = 1\nelevation_deg = 0\n";
    let e = SimConfig::parse(bad_script, Path::new("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("script[1]"), "{e}");
}

#[test]
#[ignore = "benchmark; run with --release -- --ignored"]
fn simulator_produces_a_million_samples_per_second() {
    let mut s = SimulatedFove::fove0(1);
    let start = std::time::Instant::now();
    let n = 2_000_000;
    for _ in 0..n {
        std::hint::black_box(s.step());
    }
    let rate = n as f64 / start.elapsed().as_secs_f64();
    assert!(rate > 1e6, "{rate} samples/s");
}
