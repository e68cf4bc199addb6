use super::*;
use std::f64::consts::TAU;

#[test]
fn hermite_meets_its_ends_and_slopes() {
    let (p0, p1, t0, t1) = (1.0, 3.0, 0.5, -2.0);
    assert!((hermite(p0, p1, t0, t1, 0.0) - p0).abs() < 1e-15);
    assert!((hermite(p0, p1, t0, t1, 1.0) - p1).abs() < 1e-15);
    let h = 1e-6;
    let d0 = (hermite(p0, p1, t0, t1, h) - hermite(p0, p1, t0, t1, 0.0)) / h;
    let d1 = (hermite(p0, p1, t0, t1, 1.0) - hermite(p0, p1, t0, t1, 1.0 - h)) / h;
    assert!((d0 - t0).abs() < 1e-5 && (d1 - t1).abs() < 1e-5);
}

fn track_of(segments: &str) -> Result<Track> {
    let xml = format!(
        r#"<params name="t"><section name="Main Track"><attnum name="width" unit="m" val="10"/>
        <attnum name="profil steps length" unit="m" val="4"/>
        <section name="Track Segments">{segments}</section></section></params>"#
    );
    from_params(&Params::parse(&xml, "t.xml", None)?, "t.xml", Ends::MayMiss)
}

#[test]
fn a_stadium_of_straights_and_half_circles_closes() {
    let half = r#"<attstr name="type" val="lft"/><attnum name="radius" unit="m" val="50"/><attnum name="arc" unit="deg" val="180"/>"#;
    let straight = r#"<attstr name="type" val="str"/><attnum name="lg" unit="m" val="100"/>"#;
    let t = track_of(&format!(
        r#"<section name="a">{straight}</section><section name="b">{half}</section>
           <section name="c">{straight}</section><section name="d">{half}</section>"#
    ))
    .unwrap();
    assert!((t.length - (200.0 + 100.0 * std::f64::consts::PI)).abs() < 1e-9);
    assert!(
        t.closure.gap_m < 1e-9 && t.closure.heading_deg.abs() < 1e-9,
        "{:?}",
        t.closure
    );
    assert!((t.min_radius() - 50.0).abs() < 1e-9);
}

/// A fuzzer's find: a 2·10⁵¹ m straight overflowed the count of profile steps. A segment
/// past 100 km is refused, naming it; a tiny profile step length is capped, not a panic.
#[test]
fn an_absurd_segment_length_is_an_error_and_a_tiny_step_no_panic() {
    let e = track_of(r#"<section name="s1"><attstr name="type" val="str"/><attnum name="lg" unit="m" val="2e51"/></section>"#)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("s1/lg") && e.contains("at most 100 km") && e.contains("2000000000"),
        "{e}"
    );
    let tiny = r#"<section name="s1"><attstr name="type" val="str"/><attnum name="lg" unit="m" val="100"/>
        <attnum name="profil steps length" unit="m" val="1e-300"/></section>"#;
    let _ = track_of(tiny);
}

#[test]
fn a_spiral_turns_exactly_its_arc() {
    // 90° left spiral 100 m → 200 m: TORCS keeps the arc and adjusts the length.
    let t = track_of(
        r#"<section name="s"><attstr name="type" val="lft"/><attnum name="radius" unit="m" val="100"/>
           <attnum name="end radius" unit="m" val="200"/><attnum name="arc" unit="deg" val="90"/></section>"#,
    )
    .unwrap();
    let turned: f64 = t.samples.iter().map(|c| c.curvature * t.ds).sum();
    assert!(
        (turned - std::f64::consts::FRAC_PI_2).abs() < 0.02,
        "turned {turned}"
    );
    // The mean-radius length 150·π/2 ≈ 235.6 m is only approximate for a spiral.
    assert!((t.length - 235.6).abs() < 10.0, "length {}", t.length);
}

const HALF: &str = r#"<attstr name="type" val="lft"/><attnum name="radius" unit="m" val="50"/><attnum name="arc" unit="deg" val="180"/>"#;
const STRAIGHT: &str = r#"<attstr name="type" val="str"/><attnum name="lg" unit="m" val="100"/>"#;

#[test]
fn version_3_files_keep_segments_and_surfaces_in_their_own_sections() {
    let xml = format!(
        r#"<params><section name="Surfaces"><section name="List"><section name="dirt">
             <attnum name="friction" val="0.7"/></section></section></section>
           <section name="Header"><attnum name="version" val="3"/></section>
           <section name="Main Track"><attstr name="surface" val="dirt"/>
             <section name="segments"><section name="a">{STRAIGHT}</section>
               <section name="b">{HALF}</section><section name="c">{STRAIGHT}</section>
               <section name="d">{HALF}</section></section></section></params>"#
    );
    let p = Params::parse(&xml, "v3.xml", None).unwrap();
    let t = from_params(&p, "v3.xml", Ends::MustMeet).unwrap();
    assert!((t.length - (200.0 + 100.0 * std::f64::consts::PI)).abs() < 1e-9);
    assert!(t.samples.iter().all(|c| c.friction == 0.7));
    assert!(t.warnings.is_empty(), "{:?}", t.warnings);
    // Version 4 looks for `Track Segments`, and says so.
    let v4 = xml.replace(r#"val="3""#, r#"val="4""#);
    let e = from_params(
        &Params::parse(&v4, "v4.xml", None).unwrap(),
        "v4.xml",
        Ends::MustMeet,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("Main Track/Track Segments: missing section"),
        "{e}"
    );
}

/// Borders and sides as `track4.cpp` carries them: the main track's start them, a
/// segment's change them from there on, a side's width runs from its start to its end width
/// over the segment's steps, a surface is looked up only where it has a width, a `curb`
/// border is a kerb of its `height`, and a barrier stands past them.
#[test]
fn borders_and_sides_carry_from_segment_to_segment() {
    let xml = format!(
        r#"<params><section name="Surfaces">
             <section name="kerb"><attnum name="friction" val="0.4"/>
               <attnum name="rolling resistance" val="0.05"/>
               <attnum name="roughness" unit="cm" val="5"/>
               <attnum name="roughness wavelength" val="0.3"/></section>
             <section name="sand"><attnum name="friction" val="0.6"/></section></section>
           <section name="Header"><attnum name="version" val="4"/></section>
           <section name="Main Track"><attnum name="width" val="10"/>
             <attnum name="profil steps length" val="10"/>
             <section name="Left Border"><attnum name="width" val="2"/>
               <attstr name="surface" val="kerb"/><attstr name="style" val="curb"/>
               <attnum name="height" val="0.1"/></section>
             <section name="Right Side"><attnum name="width" val="5"/>
               <attstr name="surface" val="sand"/></section>
             <section name="Track Segments"><section name="a">{STRAIGHT}</section>
               <section name="b">{STRAIGHT}
                 <section name="Left Border"><attnum name="width" val="0"/></section>
                 <section name="Left Side"><attnum name="start width" val="4"/>
                   <attnum name="end width" val="0"/><attstr name="surface" val="kerb"/>
                 </section></section>
               <section name="c">{STRAIGHT}</section></section></section></params>"#
    );
    let p = Params::parse(&xml, "sides.xml", None).unwrap();
    let t = from_params(&p, "sides.xml", Ends::MayMiss).unwrap();
    assert!(
        // Only the road's `asphalt` is missing; the unused default `grass` is not looked up.
        t.warnings.iter().all(|w| !w.contains("grass")),
        "{:?}",
        t.warnings
    );
    let at = |s: f64| t.sample(t.index_at(s)).verges;
    let [left, right] = at(50.0);
    assert_eq!((left.border_width, left.border.friction), (2.0, 0.4));
    assert_eq!(left.border.rolling_resistance, Some(0.05));
    // A `curb` border is a raised kerb of its `height`; no border, no kerb.
    assert_eq!((left.kerb_height, right.kerb_height), (0.1, 0.0));
    assert_eq!(left.side_width, 0.0);
    assert_eq!((right.side_width, right.side.friction), (5.0, 0.6));
    assert_eq!(right.border_width, 0.0);
    assert_eq!(left.surface_at(1.0).unwrap().friction, 0.4);
    assert_eq!(left.surface_at(3.0).unwrap().friction, 0.4);
    assert_eq!(right.surface_at(0.5).unwrap().friction, 0.6);
    // The kerb's 5 cm at 0.3 m: A = 2.5 cm, k = 2π/0.3; the sand is smooth.
    let r = left.border.roughness;
    assert!((r.amplitude - 0.025).abs() < 1e-15 && (r.wavenumber - TAU / 0.3).abs() < 1e-12);
    assert!(!right.side.roughness.is_rough());
    // Segment b: no border; a side narrowing from 4 m to 0 over its 11 steps, step 0 at
    // 4·(1 − 0.5/11).
    let [left, right] = at(104.0);
    assert_eq!((left.border_width, left.kerb_height), (0.0, 0.0));

    assert!(
        (left.side_width - 4.0 * (1.0 - 0.5 / 11.0)).abs() < 1e-9,
        "{left:?}"
    );
    assert_eq!(left.side.friction, 0.4);
    assert_eq!(right.side.friction, 0.6);
    // Segment c carries b's end: no side and no border on the left.
    let [left, _] = at(250.0);
    assert_eq!((left.border_width, left.side_width), (0.0, 0.0));
    assert_eq!(left.surface_at(1.0), None);
    // A barrier closes each side: past the road's 5 m half-width, the border and the side.
    let barriers = |s: f64| t.frame(t.index_at(s)).barriers;
    assert_eq!(barriers(50.0), [5.0 + 2.0, 5.0 + 5.0]);
    assert_eq!(barriers(250.0), [5.0, 5.0 + 5.0]);
}

/// A roughness past its bound or a wavelength of 0 is refused, naming the surface's
/// element and the value.
#[test]
fn a_rough_surface_out_of_bounds_is_refused() {
    for (field, val, says) in [
        (
            "roughness",
            "-0.01",
            "roughness must be in [0, 1] m, got -0.01 m",
        ),
        ("roughness", "2", "roughness must be in [0, 1] m, got 2 m"),
        (
            "roughness wavelength",
            "0",
            "roughness wavelength must be positive, got 0 m",
        ),
    ] {
        let xml = format!(
            r#"<params><section name="Surfaces"><section name="asphalt">
               <attnum name="{field}" val="{val}"/></section></section>
               <section name="Main Track"><section name="Track Segments">
               <section name="a">{STRAIGHT}</section></section></section></params>"#
        );
        let p = Params::parse(&xml, "rough.xml", None).unwrap();
        let e = from_params(&p, "rough.xml", Ends::MayMiss)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&format!("rough.xml:2: Surfaces/asphalt/{field}")) && e.contains(says),
            "{e}"
        );
    }
}

#[test]
fn a_track_that_does_not_close_is_refused_unless_asked_for() {
    // The stadium without its last half circle: its end is 100 m from its start.
    let segs = format!(
        r#"<section name="a">{STRAIGHT}</section><section name="b">{HALF}</section>
           <section name="c">{STRAIGHT}</section>"#
    );
    let xml = format!(
        r#"<params name="t"><section name="Main Track">
        <section name="Track Segments">{segs}</section></section></params>"#
    );
    let p = Params::parse(&xml, "open.xml", None).unwrap();
    let e = from_params(&p, "open.xml", Ends::MustMeet)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("open.xml:2: Main Track/Track Segments: not a circuit")
            && e.contains("by 100.00 m and -180.00°"),
        "{e}"
    );
    let t = from_params(&p, "open.xml", Ends::MayMiss).unwrap();
    assert!(
        t.warnings.iter().any(|w| w.contains("open track")),
        "{:?}",
        t.warnings
    );
}

#[test]
fn a_bad_value_names_its_own_line() {
    let e = track_of(
        "<section name=\"s\">\n<attstr name=\"type\" val=\"lft\"/>\n<attnum name=\"radius\" val=\"-5\"/>\n<attnum name=\"arc\" val=\"1\"/></section>",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("t.xml:5: ") && e.contains("radii must be positive"),
        "{e}"
    );
}

#[test]
fn grade_carries_over_and_builds_height() {
    let t = track_of(
        r#"<section name="a"><attstr name="type" val="str"/><attnum name="lg" unit="m" val="100"/>
           <attnum name="grade" unit="%" val="2"/></section>
           <section name="b"><attstr name="type" val="str"/><attnum name="lg" unit="m" val="100"/></section>"#,
    )
    .unwrap();
    let (lo, hi) = t.z_range();
    assert!(lo.abs() < 1e-9);
    assert!((hi - 4.0).abs() < 0.05, "z max {hi}");
}

#[test]
fn malformed_segments_name_their_element() {
    let e = track_of(r#"<section name="bad one"><attstr name="type" val="lft"/><attnum name="arc" unit="deg" val="9"/></section>"#)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("t.xml") && e.contains("Main Track/Track Segments/bad one/radius"),
        "{e}"
    );
    let e = track_of(r#"<section name="x"><attstr name="type" val="zigzag"/></section>"#)
        .unwrap_err()
        .to_string();
    assert!(e.contains("zigzag"), "{e}");
    let e = track_of("").unwrap_err().to_string();
    assert!(e.contains("no segments"), "{e}");
}
