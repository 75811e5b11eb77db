use super::files::{Axes, Job, Part, JOBS_FILE};
use super::open::check_jobs_file;
use super::plan::{flag_value, set_flag, studies};
use super::status::array_chunks;

fn words(s: &str) -> Vec<String> {
    s.split_whitespace().map(str::to_string).collect()
}

#[test]
fn flags_are_found_and_replaced_in_both_spellings() {
    let args = words("quality --scene a --width=64 --methods vp,cartesian --scene=b");
    assert_eq!(flag_value(&args, "--scene").as_deref(), Some("b"));
    assert_eq!(flag_value(&args, "--width").as_deref(), Some("64"));
    assert_eq!(flag_value(&args, "--height"), None);
    assert_eq!(
        set_flag(&args, "--scene", "c"),
        words("quality --width=64 --methods vp,cartesian --scene c")
    );
    assert_eq!(
        set_flag(&args, "--methods", "vp"),
        words("quality --scene a --width=64 --scene=b --methods vp")
    );
}

#[test]
fn axes_make_one_study_each_with_the_merged_output_as_out() {
    let axes = Axes {
        scenes: words("cornell-box scenes/stress.gltf"),
        headsets: vec![],
        gazes: words("sim:1 center"),
    };
    let s = studies(&words("quality --width 64 --methods vp"), &axes).unwrap();
    let names: Vec<&str> = s.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "cornell-box_sim-1",
            "cornell-box_center",
            "stress_sim-1",
            "stress_center"
        ]
    );
    assert_eq!(
        s[2].args,
        words(
            "quality --width 64 --methods vp --scene scenes/stress.gltf --gaze sim:1 \
             --out merged/stress_sim-1"
        )
    );
    assert_eq!(s[2].merged, "merged/stress_sim-1");
    let r = studies(&words("reference --spp 64"), &Axes::default()).unwrap();
    assert_eq!(r[0].name, "cornell-box");
    assert_eq!(
        r[0].args,
        words("reference --spp 64 --out merged/cornell-box/reference.exr")
    );
}

#[test]
fn bad_commands_and_axes_are_refused_with_the_flag() {
    let err =
        |command: &str, axes: Axes| format!("{:#}", studies(&words(command), &axes).unwrap_err());
    assert!(
        err("render --frames 2", Axes::default()).contains("`render --frames 2` is none of them")
    );
    assert!(err("quality --out x", Axes::default()).contains("leave --out out"));
    let scenes = Axes {
        scenes: words("cornell-box"),
        ..Axes::default()
    };
    assert!(err("quality --scene stress", scenes).contains("--scene in the command and --scenes"));
    let gazes = Axes {
        gazes: words("center"),
        ..Axes::default()
    };
    assert!(err("reference --spp 4", gazes).contains("a reference has no gaze"));
    let replay_scenes = Axes {
        scenes: words("cornell-box"),
        ..Axes::default()
    };
    assert!(err("replay sim:1 --baseline b", replay_scenes).contains("a replay sweep has no axes"));
    let twins = Axes {
        scenes: words("a/x.gltf b/x.gltf"),
        ..Axes::default()
    };
    assert!(err("quality", twins).contains("two studies are named x"));
}

#[test]
fn slurm_arrays_are_ranges_below_the_array_size_limit() {
    assert_eq!(
        array_chunks(&[0, 1, 2, 5, 7, 8], 1001).unwrap(),
        [(0, "0-2,5,7-8".to_string())]
    );
    assert_eq!(
        array_chunks(&[3, 4, 5, 6, 9], 3).unwrap(),
        [
            (3, "0-2".to_string()),
            (6, "0".to_string()),
            (9, "0".to_string())
        ]
    );
    assert!(array_chunks(&[], 1001).unwrap().is_empty());
    assert!(array_chunks(&[1], 1).is_err());
}

fn job(index: u32) -> Job {
    Job {
        index,
        stage: "run".into(),
        name: format!("job {index}"),
        study: 0,
        args: words("quality --methods vp"),
        part: Part::Run {
            camera: "still".into(),
            method: "vp".into(),
            denoiser: "none".into(),
            taa: "off".into(),
            noise: None,
        },
        out: format!("jobs/{index:04}"),
        after: vec![],
    }
}

#[test]
fn an_edited_jobs_file_is_named_by_line_and_field() {
    let dir = std::env::temp_dir().join(format!("fovea-sweep-jobs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(JOBS_FILE);
    let jobs = vec![job(0), job(1)];
    let lines = |jobs: &[Job]| -> String {
        jobs.iter()
            .map(|j| serde_json::to_string(j).unwrap() + "\n")
            .collect()
    };
    std::fs::write(&path, lines(&jobs)).unwrap();
    check_jobs_file(&path, &jobs).unwrap();
    let mut edited = jobs.clone();
    edited[1].args = words("quality --methods cartesian");
    std::fs::write(&path, lines(&edited)).unwrap();
    let e = format!("{:#}", check_jobs_file(&path, &jobs).unwrap_err());
    assert!(e.contains("line 2 (job 1): field `args`"), "{e}");
    std::fs::write(&path, lines(&jobs[..1])).unwrap();
    let e = format!("{:#}", check_jobs_file(&path, &jobs).unwrap_err());
    assert!(
        e.contains("1 lines, the plan in sweep.json makes 2 jobs"),
        "{e}"
    );
    std::fs::write(&path, "{\"index\":0}\nnot json\n").unwrap();
    let e = format!("{:#}", check_jobs_file(&path, &jobs).unwrap_err());
    assert!(
        e.contains("line 1 (job 0): field `after` is missing"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
