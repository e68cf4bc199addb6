//! Traces and figures: a lap's trace and plot, a track's map with a trace or a line, a race's
//! figures, and a plot into a missing folder refused in one line.

use std::path::Path;

use crate::common::{fails_with, oval_file, scratch, succeed};

#[test]
fn traces_and_plots_are_written() {
    let trace = scratch("lap.csv", "");
    let png = scratch("lap.png", "");
    let svg = scratch("map.svg", "");
    succeed(&[
        "lap",
        "--trace",
        trace.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&trace).unwrap();
    assert!(text.starts_with("t_s,distance_m,x,speed_mps") && text.lines().count() > 1000);
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
    succeed(&[
        "plot",
        "track",
        "ridgeway",
        "-o",
        svg.to_str().unwrap(),
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    let lined = scratch("line.svg", "");
    succeed(&[
        "plot",
        "track",
        "ridgeway",
        "-o",
        lined.to_str().unwrap(),
        "--line",
        "min-curvature",
    ]);
    let text = std::fs::read_to_string(&lined).unwrap();
    assert!(
        text.contains("magenta: the minimum-curvature line"),
        "{text}"
    );
}

/// A plot into a folder that does not exist names the file and the folder, in one line.
#[test]
fn a_plot_into_a_missing_folder_names_the_path() {
    fails_with(
        &["plot", "track", "ridgeway", "-o", "/missing/dir/x.svg"],
        &["/missing/dir/x.svg", "/missing/dir does not exist"],
    );
    fails_with(
        &["plot", "track", "ridgeway", "-o", "/missing/dir/x.png"],
        &["/missing/dir/x.png", "does not exist"],
    );
}

#[test]
fn a_race_draws_its_figures() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-race-plots-{}", std::process::id()));
    succeed(&[
        "race",
        "--track",
        oval_file(),
        "--laps",
        "12",
        "--kernels",
        "8",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    for name in ["learning_curve", "policy", "speed", "map"] {
        assert_eq!(
            &std::fs::read(out.join(format!("{name}.png"))).unwrap()[1..4],
            b"PNG",
            "{name}"
        );
        assert!(
            std::fs::read_to_string(out.join(format!("{name}.svg")))
                .unwrap()
                .contains("<svg"),
            "{name}"
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}
