//! No-panic property tests over the trace parser, the importers and the TOML loaders
//! (a cargo-fuzz substitute that runs in the ordinary test suite).

use fovea_hal::trace::import::{
    import_gazebase_text, import_normalized_text, DegreesImport, NormalizedImport,
};
use fovea_hal::{Fov, GazeSpec, HmdDescription, SimConfig, Trace};
use proptest::prelude::*;
use std::path::Path;

const TRACE_HEAD: &str =
    "# fovea-gaze-trace 1\n# device: x\n# rate_hz: 120\n# coordinates: openxr-view\n";

fn fragment() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("0".to_string()),
        Just("1".to_string()),
        Just("-1".to_string()),
        Just("NaN".to_string()),
        Just("inf".to_string()),
        Just("".to_string()),
        Just("open".to_string()),
        Just("measured".to_string()),
        Just("9223372036854775807".to_string()),
        Just("-0".to_string()),
        Just("1e39".to_string()),
        "[ -~]{0,6}",
        any::<f32>().prop_map(|f| f.to_string()),
        any::<i64>().prop_map(|i| i.to_string()),
    ]
}

fn row() -> impl Strategy<Value = String> {
    prop::collection::vec(fragment(), 0..30).prop_map(|v| v.join(","))
}

fn columns() -> impl Strategy<Value = String> {
    let names = fovea_hal::trace::COLUMNS
        .iter()
        .map(|s| s.to_string())
        .collect::<Vec<_>>();
    prop::sample::subsequence(names, 0..=27).prop_map(|v| v.join(","))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, .. ProptestConfig::default() })]

    #[test]
    fn trace_parser_never_panics_on_arbitrary_text(text in "\\PC{0,400}") {
        let _ = Trace::parse(&text, Path::new("fuzz.csv"));
    }

    #[test]
    fn trace_parser_never_panics_on_structured_rows(cols in columns(), rows in prop::collection::vec(row(), 0..8), nl in any::<bool>()) {
        let mut text = format!("{TRACE_HEAD}{cols}\n{}", rows.join("\n"));
        if nl { text.push('\n'); }
        if let Ok(t) = Trace::parse(&text, Path::new("fuzz.csv")) {
            // Whatever parses must write and parse back identically.
            let again = Trace::parse(&t.to_text(), Path::new("again.csv")).unwrap();
            prop_assert!(again.samples.iter().zip(&t.samples).all(|(a, b)| a.bit_eq(b)));
        }
    }

    #[test]
    fn importers_never_panic(rows in prop::collection::vec(row(), 0..8)) {
        let body = rows.join("\n");
        let _ = import_gazebase_text(&format!("n,x,y,val,lx,ly,rx,ry\n{body}"), Path::new("g.csv"), &DegreesImport::default());
        let fov = Fov::from_degrees(-40.0, 40.0, -40.0, 40.0);
        let _ = import_normalized_text(&format!("time_ms,x,y\n{body}"), Path::new("n.csv"), &NormalizedImport::new("n", fov));
    }

    #[test]
    fn headset_loader_never_panics(text in "\\PC{0,300}") {
        let _ = HmdDescription::parse(&text, Path::new("fuzz.toml"));
        let _ = SimConfig::parse(&text, Path::new("fuzz.toml"));
        let _ = text.parse::<GazeSpec>();
    }

    #[test]
    fn headset_loader_never_panics_on_mutated_values(
        key in prop::sample::select(vec!["refresh_hz", "recommended_width", "left", "right", "down", "up", "rate_hz", "latency_ms", "accuracy_deg", "offset_m"]),
        value in prop_oneof![Just("nan".to_string()), Just("inf".to_string()), Just("-inf".to_string()), Just("[]".to_string()), Just("\"x\"".to_string()),
                             any::<f32>().prop_map(|f| format!("{f:?}")), any::<i64>().prop_map(|i| i.to_string())],
    ) {
        let base = include_str!("../../config/headsets/varjo_aero.toml");
        let mutated: String = base.lines().map(|l| {
            let t = l.trim_start();
            if t.starts_with(&format!("{key} =")) { format!("{key} = {value}") } else { l.replace(&format!("{key} = "), &format!("{key} = {value}, _old = ")) }
        }).collect::<Vec<_>>().join("\n");
        if let Ok(h) = HmdDescription::parse(&mutated, Path::new("fuzz.toml")) {
            // Anything accepted is usable: conversions stay finite at the image centre.
            for v in &h.eyes {
                let c = glam::Vec2::new(v.recommended_width as f32 / 2.0, v.recommended_height as f32 / 2.0);
                prop_assert!(v.pixel_to_direction(c).is_finite());
            }
        }
    }
}
