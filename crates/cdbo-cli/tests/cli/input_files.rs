//! Files and sources a user hands the command line: a hand-written track loads; a bad track
//! file, an endless input or a bad dashboard source is refused in one line naming it.

use std::path::Path;

use crate::common::{OVAL as TRACK, fails_with, json, run, scratch};

#[test]
fn a_hand_written_track_file_loads() {
    let p = scratch("oval.xml", TRACK);
    let v = json(&["track", "info", p.to_str().unwrap(), "--json"]);
    assert!(
        (v["length_m"].as_f64().unwrap() - (200.0 + 100.0 * std::f64::consts::PI)).abs() < 1e-6
    );
}

#[test]
fn bad_track_files_give_one_clear_error() {
    let truncated = scratch("truncated.xml", &TRACK[..TRACK.len() / 2]);
    fails_with(
        &["track", "info", truncated.to_str().unwrap()],
        &["truncated.xml"],
    );
    let no_radius = scratch(
        "noradius.xml",
        &TRACK.replacen(r#"<attnum name="radius" unit="m" val="50"/>"#, "", 1),
    );
    fails_with(
        &["track", "info", no_radius.to_str().unwrap()],
        &[
            "noradius.xml",
            "Main Track/Track Segments/c1/radius",
            "missing",
        ],
    );
    let bad_unit = scratch(
        "badunit.xml",
        &TRACK.replacen(r#"unit="deg""#, r#"unit="gradians""#, 1),
    );
    fails_with(
        &["track", "info", bad_unit.to_str().unwrap()],
        &["badunit.xml", "c1/arc", "gradians"],
    );
    let nan = scratch(
        "nan.csv",
        "# x_m,y_m,w_tr_right_m,w_tr_left_m\n0,0,5,5\n1,NaN,5,5\n",
    );
    fails_with(
        &["track", "info", nan.to_str().unwrap()],
        &["nan.csv:3", "NaN"],
    );
    let few = scratch("few.csv", "0,0,5,5\n10,0,5,5\n10,10,5,5\n");
    fails_with(
        &["track", "info", few.to_str().unwrap()],
        &["few.csv", "at least 10 points"],
    );
    fails_with(
        &["track", "info", "atlantis"],
        &["unknown track", "atlantis", "ridgeway"],
    );
    fails_with(
        &["lap", "--car", "no-such-car"],
        &["unknown car", "no-such-car"],
    );
    fails_with(&["lap", "--throttle", "3"], &["--throttle"]);
    fails_with(&["lap", "--demo", "-5"], &["--demo"]);
}

#[test]
fn dashboard_refuses_bad_sources_and_a_port_in_use_in_one_line() {
    let missing = scratch("dash-gone", "");
    std::fs::remove_file(&missing).unwrap();
    let missing = missing.to_str().unwrap();
    fails_with(&["dashboard", "--db", missing], &[missing, "no such study"]);
    let words = scratch("dash-notes.txt", "not a study, only words\n");
    let words = words.to_str().unwrap();
    fails_with(&["dashboard", "--db", words], &[words, "not a cdbo study"]);
    fails_with(
        &["dashboard", "--experiment", missing],
        &[missing, "no such folder"],
    );
    fails_with(&["dashboard"], &["nothing to show"]);
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap().to_string();
    let dir = env!("CARGO_TARGET_TMPDIR").to_owned();
    fails_with(
        &["dashboard", "--experiment", &dir, "--bind", &addr],
        &[&addr, "in use"],
    );
    fails_with(
        &["dashboard", "--experiment", &dir, "--bind", "localhost"],
        &["--bind", "localhost", "an address and port"],
    );
}

/// Runs, expects failure with stderr exactly one `error:` line refusing `input` as larger than
/// `bound` (e.g. `16 MiB`).
fn refused_as_too_large(args: &[&str], input: &str, bound: &str) {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "{args:?}: not one line: {err}");
    assert!(lines[0].starts_with("error: "), "{args:?}: {err}");
    assert!(
        lines[0].contains(input)
            && lines[0].ends_with(&format!("is larger than its bound of {bound}")),
        "{args:?}: {:?} does not refuse {input} past {bound}",
        lines[0]
    );
}

/// Every file a command reads is read through its bound: an endless one (`/dev/zero`,
/// `/dev/urandom`, or a link to them named as the flag expects) and one past its bound
/// (a sparse file, as a car's category or a track's included entity) are refused in one line
/// naming the file and the bound, instead of being read forever.
#[test]
fn endless_input_files_are_refused_at_their_bound() {
    let dir = scratch("endless", "")
        .parent()
        .unwrap()
        .join("endless-files");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let zero = |name: &str| {
        let p = dir.join(name);
        std::os::unix::fs::symlink("/dev/zero", &p).unwrap();
        p.to_str().unwrap().to_owned()
    };
    let (json, xml, csv) = (zero("zero.json"), zero("zero.xml"), zero("zero.csv"));
    let out = dir.join("out.json");
    let out = out.to_str().unwrap();

    refused_as_too_large(
        &["lap", "--policy", "/dev/urandom"],
        "/dev/urandom: the policy table",
        "64 MiB",
    );
    refused_as_too_large(
        &["lap", "--policy", &json],
        "zero.json: the policy file",
        "1 MiB",
    );
    refused_as_too_large(
        &["lap", "--track", &xml],
        "zero.xml: the track file",
        "16 MiB",
    );
    refused_as_too_large(
        &["lap", "--track", &csv],
        "zero.csv: the track centre-line file",
        "64 MiB",
    );
    refused_as_too_large(&["lap", "--car", &xml], "zero.xml: the car file", "16 MiB");
    refused_as_too_large(
        &["experiment", "/dev/zero"],
        "/dev/zero: the experiment grid file",
        "1 MiB",
    );
    refused_as_too_large(
        &[
            "policy",
            "fit",
            "--demo",
            "/dev/zero",
            "--kernels",
            "10",
            "-o",
            out,
        ],
        "/dev/zero: the demonstration file",
        "256 MiB",
    );
    refused_as_too_large(
        &["policy", "table", "/dev/zero"],
        "/dev/zero: the policy file",
        "1 MiB",
    );
    refused_as_too_large(
        &[
            "study",
            "create",
            "s",
            "--kernels",
            "6",
            "--demo",
            "/dev/zero",
        ],
        "/dev/zero: the demonstration file",
        "256 MiB",
    );
    refused_as_too_large(
        &[
            "plot",
            "track",
            "ridgeway",
            "-o",
            out,
            "--trace",
            "/dev/zero",
        ],
        "/dev/zero: the trace file",
        "256 MiB",
    );
    std::fs::create_dir_all(dir.join("grid/runs")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", dir.join("grid/runs/run.json")).unwrap();
    refused_as_too_large(
        &["report", dir.join("grid").to_str().unwrap()],
        "run.json: the run record",
        "64 MiB",
    );

    // Files past their bound where only a regular file is read: a car's category file and a
    // track's included entity, each a sparse file of 16 MiB and one byte.
    let sparse = |path: &Path| {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::File::create(path)
            .and_then(|f| f.set_len((16 << 20) + 1))
            .unwrap();
    };
    sparse(&dir.join("categories/big.xml"));
    let car = dir.join("cars/c/c.xml");
    std::fs::create_dir_all(car.parent().unwrap()).unwrap();
    std::fs::write(
        &car,
        r#"<params name="c"><section name="Car"><attstr name="category" val="big"/></section></params>"#,
    )
    .unwrap();
    refused_as_too_large(
        &["lap", "--car", car.to_str().unwrap()],
        "big.xml: the car category file",
        "16 MiB",
    );
    sparse(&dir.join("tracks/surfaces.xml"));
    let track = dir.join("tracks/t.xml");
    std::fs::write(
        &track,
        TRACK.replacen(
            "<params name=\"t\">",
            "<!DOCTYPE params SYSTEM \"params.dtd\" [\n<!ENTITY surfaces SYSTEM \"surfaces.xml\">\n]>\n<params name=\"t\">&surfaces;",
            1,
        ),
    )
    .unwrap();
    refused_as_too_large(
        &["track", "info", track.to_str().unwrap()],
        "surfaces.xml: the included entity file",
        "16 MiB",
    );
    let _ = std::fs::remove_dir_all(&dir);
}
