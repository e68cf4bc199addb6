//! TORCS / Speed Dreams track files (`tracks/road/NAME/NAME.xml`).
//!
//! `Header/version` chooses the layout, as TORCS's `TrackBuildv1` does: versions 0–3
//! (`track3.cpp`) keep the segments in `Main Track/segments` and the surfaces in
//! `Surfaces/List`, where a `z start` / `z end` sets both edges (so the banking defaults to
//! level); version 4 and up (`track4.cpp`, Speed Dreams' 5) use `Main Track/Track Segments`
//! and `Surfaces`. A file without a version uses whichever segment list it has.
//!
//! Both follow the same rules otherwise, so lengths equal the game's:
//! - `str`: length `lg`. `lft` / `rgt`: radius r, `end radius` r₁ (default r), `arc` α;
//!   nominal length (r + r₁)/2 · α.
//! - Each segment is cut into `steps` = ⌊length / `profil steps length`⌋ + 1 sub-segments (or
//!   `profil steps`). With r₁ ≠ r the radius grows linearly, rᵢ = r + i·(r₁ − r)/(steps − 1),
//!   and the common sub-segment length ℓ is scaled so that Σ ℓ/rᵢ = α.
//! - Heights: `z start` / `z end` (or left/right variants), else `grade` (kept from segment to
//!   segment) gives z_end = z_start + length·grade; left and right edges follow cubic Hermite
//!   profiles with `profil start/end tangent`; `banking start/end` override the edge heights.
//!   Banking is atan((z_left − z_right) / width).
//! - Road friction, rolling resistance and roughness are the `friction`, `rolling resistance`
//!   and `roughness` / `roughness wavelength` of the segment's `surface` in the `Surfaces`
//!   section (simuv2 takes all three from the road; [`super::Roughness`]).
//! - Past each edge (version 4 and up; `track4.cpp`'s `InitSides` and `AddSides`), a border and
//!   a side ([`super::Verge`]): `Main Track/Left Border` (`width`, default 0; `surface`,
//!   default `grass`) and `Main Track/Left Side` (`width`, default 0; `surface`, default
//!   `grass`) start them, and each segment's own `Left Border` / `Left Side` sections change
//!   them from there on: the border's `width` and `surface` carry over; the side's width runs
//!   from `start width` (default the previous end width) through `width` (default the start
//!   width) to `end width` (default `width`), linearly over the segment's steps, and its
//!   `surface` carries over. Likewise on the right. A barrier closes each side
//!   ([`super::Verge::barrier`]).

use std::path::Path;

use std::collections::HashMap;

use super::{Ends, MAX_LENGTH_M, Piece, Roughness, Surface, Track, Verge};
use crate::bounded;
use crate::error::Result;
use crate::params::{Params, Section};

/// Reads a TORCS track file; `ends` says what to do when it does not close.
pub fn read(path: &Path, ends: Ends) -> Result<Track> {
    let params = Params::read(path, &bounded::TRACK_FILE)?;
    from_params(&params, &path.display().to_string(), ends)
}

/// Builds a track from parsed parameters; `source` is recorded in the track. A track whose end
/// misses its start is refused, or loaded with a warning when `ends` is [`Ends::MayMiss`].
pub fn from_params(params: &Params, source: &str, ends: Ends) -> Result<Track> {
    let file = params.file.as_str();
    let mut warnings = params.warnings.clone();
    let main = params.require_section("Main Track")?;
    let width = main.num_or("width", 15.0)?;
    if width <= 0.0 {
        return Err(params.error(
            "Main Track/width",
            Some(main.line_of("width")),
            format!("width must be positive, got {width} m"),
        ));
    }
    let global_step = main.num_or("profil steps length", 0.0)?;
    let layout = Layout::of(params)?;
    let segments = params.require_section(layout.segments())?;
    if segments.sections.is_empty() {
        return Err(params.error(&segments.path, Some(segments.line), "no segments"));
    }
    let mut surface = main.str("surface").unwrap_or("asphalt").to_owned();
    let mut state = ProfileState {
        sides_follow_z: layout == Layout::V3,
        ..ProfileState::default()
    };
    let mut pieces = Vec::new();
    let mut sides = if layout == Layout::V4 {
        Some(Sides::of(main)?)
    } else {
        None
    };
    let mut surfaces = HashMap::new();
    for seg in &segments.sections {
        if let Some(name) = seg.str("surface") {
            surface = name.to_owned();
        }
        let road = surface_of(params, &surface, &mut warnings, false)?;
        let first = pieces.len();
        segment_pieces(
            params,
            seg,
            width,
            global_step,
            road,
            &mut state,
            &mut pieces,
        )?;
        if let Some(sides) = sides.as_mut() {
            sides.update(seg)?;
            let steps = pieces.len() - first;
            for (i, piece) in pieces[first..].iter_mut().enumerate() {
                let t = (i as f64 + 0.5) / steps as f64;
                for k in 0..2 {
                    piece.verges[k] = sides.verge(k, t, &mut |name: &str| {
                        resolve(params, name, &mut surfaces, &mut warnings)
                    })?;
                }
            }
        }
    }
    let length: f64 = pieces.iter().map(|p| p.length).sum();
    if length > MAX_LENGTH_M {
        return Err(params.error(
            &segments.path,
            Some(segments.line),
            format!("the track is {length:.0} m long, more than {MAX_LENGTH_M} m"),
        ));
    }
    let name = params
        .section("Header")
        .and_then(|h| h.str("name"))
        .map(str::to_owned)
        .unwrap_or_else(|| {
            Path::new(source)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        });
    let mut track = Track::from_pieces(&name, source, &pieces, warnings);
    if !track.closure.is_closed() {
        match ends {
            Ends::MustMeet => {
                return Err(params.error(
                    &segments.path,
                    Some(segments.line),
                    format!("not a circuit: {}", track.closure.describe()),
                ));
            }
            Ends::MayMiss => track.warnings.push(format!(
                "{file}: an open track: {}",
                track.closure.describe()
            )),
        }
    }
    Ok(track)
}

/// Where a track file keeps its segments and surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Layout {
    /// Versions 0–3 (`track3.cpp`).
    V3,
    /// Versions 4 and up (`track4.cpp`).
    V4,
}

impl Layout {
    const V3_SEGMENTS: &str = "Main Track/segments";
    const V4_SEGMENTS: &str = "Main Track/Track Segments";

    fn of(params: &Params) -> Result<Layout> {
        let header = params.section("Header");
        match header.map(|h| h.num("version")).transpose()? {
            Some(Some(v)) if v < 4.0 => Ok(Layout::V3),
            Some(Some(_)) => Ok(Layout::V4),
            _ if params.section(Self::V4_SEGMENTS).is_none()
                && params.section(Self::V3_SEGMENTS).is_some() =>
            {
                Ok(Layout::V3)
            }
            _ => Ok(Layout::V4),
        }
    }

    fn segments(self) -> &'static str {
        match self {
            Layout::V3 => Self::V3_SEGMENTS,
            Layout::V4 => Self::V4_SEGMENTS,
        }
    }
}

/// A named surface (in `Surfaces` or, for version 3, `Surfaces/List`): its friction, rolling
/// resistance and roughness; friction 1.0, the tyres' rolling resistance and a smooth surface,
/// with a warning, when the surface is not defined. A road's friction must be positive; a
/// verge's may be 0 (the `armco` and `barrier` of a wall that stands as a border: Brondehach,
/// Corkscrew). The roughness must be ≥ 0 and its wavelength positive.
fn surface_of(
    params: &Params,
    surface: &str,
    warnings: &mut Vec<String>,
    verge: bool,
) -> Result<Surface> {
    let surfaces = params.section("Surfaces");
    let found = surfaces
        .and_then(|s| s.section(surface))
        .or_else(|| surfaces.and_then(|s| s.section("List")?.section(surface)));
    let Some(sec) = found else {
        let w = format!(
            "{}: surface {surface:?} is not defined, friction 1.0 assumed",
            params.file
        );
        if !warnings.contains(&w) {
            warnings.push(w);
        }
        return Ok(Surface::PLAIN);
    };
    let refuse = |field: &str, msg: String| {
        params.error(
            &format!("{}/{field}", sec.path),
            Some(sec.line_of(field)),
            msg,
        )
    };
    let friction = sec.num_or("friction", 1.0)?;
    if friction < 0.0 || (friction == 0.0 && !verge) || !friction.is_finite() {
        return Err(refuse(
            "friction",
            format!("friction must be positive, got {friction}"),
        ));
    }
    let rolling_resistance = match sec.num("rolling resistance")? {
        Some(r) if !(0.0..1.0).contains(&r) => {
            return Err(refuse(
                "rolling resistance",
                format!("rolling resistance must be in [0, 1), got {r}"),
            ));
        }
        r => r,
    };
    let roughness = sec.num_or("roughness", 0.0)?;
    if !(0.0..=MAX_ROUGHNESS_M).contains(&roughness) {
        return Err(refuse(
            "roughness",
            format!("roughness must be in [0, {MAX_ROUGHNESS_M}] m, got {roughness} m"),
        ));
    }
    let wavelength = sec.num_or("roughness wavelength", 1.0)?;
    if !(wavelength > 0.0 && wavelength.is_finite()) {
        return Err(refuse(
            "roughness wavelength",
            format!("roughness wavelength must be positive, got {wavelength} m"),
        ));
    }
    Ok(Surface {
        friction,
        rolling_resistance,
        roughness: Roughness::from_file(roughness, wavelength),
    })
}

/// The roughest surface a file may give (m): TORCS's roughest, gravel's, is 6 cm; a metre is a
/// mistake in the file (a unit left out), not a surface.
const MAX_ROUGHNESS_M: f64 = 1.0;

/// A named surface, looked up once per track.
fn resolve(
    params: &Params,
    name: &str,
    cache: &mut HashMap<String, Surface>,
    warnings: &mut Vec<String>,
) -> Result<Surface> {
    if let Some(s) = cache.get(name) {
        return Ok(*s);
    }
    let s = surface_of(params, name, warnings, true)?;
    cache.insert(name.to_owned(), s);
    Ok(s)
}

/// The borders and sides as `track4.cpp` carries them from segment to segment, `[left, right]`.
#[derive(Debug, Clone)]
struct Sides {
    border_width: [f64; 2],
    border_surface: [String; 2],
    /// The borders' `height`s, and whether their `style` is `curb` (a kerb).
    border_height: [f64; 2],
    curb: [bool; 2],
    side_start: [f64; 2],
    side_end: [f64; 2],
    side_surface: [String; 2],
}

impl Sides {
    const SIDE: [&str; 2] = ["Left Side", "Right Side"];
    const BORDER: [&str; 2] = ["Left Border", "Right Border"];

    /// `InitSides`: the main track's `Left Side`, `Left Border` (and right), width 0 and
    /// surface `grass` by default.
    fn of(main: &Section) -> Result<Sides> {
        let mut s = Sides {
            border_width: [0.0; 2],
            border_surface: [String::new(), String::new()],
            border_height: [0.0; 2],
            curb: [false; 2],
            side_start: [0.0; 2],
            side_end: [0.0; 2],
            side_surface: [String::new(), String::new()],
        };
        for k in 0..2 {
            (s.side_surface[k], s.side_end[k]) = Self::part(main.section(Self::SIDE[k]))?;
            s.side_start[k] = s.side_end[k];
            (s.border_surface[k], s.border_width[k]) = Self::part(main.section(Self::BORDER[k]))?;
            if let Some(border) = main.section(Self::BORDER[k]) {
                s.border_style(k, border)?;
            }
        }
        Ok(s)
    }

    /// A side's or border's surface (`grass` where it names none) and width (0 where the
    /// section or its width is absent) in the main track section.
    fn part(section: Option<&Section>) -> Result<(String, f64)> {
        Ok((
            section
                .and_then(|x| x.str("surface"))
                .unwrap_or("grass")
                .into(),
            section
                .map(|x| x.num_or("width", 0.0))
                .transpose()?
                .unwrap_or(0.0),
        ))
    }

    /// Border `k`'s `height` and `style` from its section, each kept where it names none (as
    /// `track4.cpp` carries them from segment to segment; `plan` and 0 at first).
    fn border_style(&mut self, k: usize, border: &Section) -> Result<()> {
        self.border_height[k] = border.num_or("height", self.border_height[k])?;
        if let Some(style) = border.str("style") {
            self.curb[k] = style == "curb";
        }
        Ok(())
    }

    /// `AddSides` at a segment's first step: its own `Left Side` / `Left Border` (and right).
    fn update(&mut self, seg: &Section) -> Result<()> {
        for k in 0..2 {
            let end = self.side_end[k];
            let (sw, ew) = match seg.section(Self::SIDE[k]) {
                Some(side) => {
                    let sw = side.num_or("start width", end)?;
                    let w = side.num_or("width", sw)?;
                    if let Some(name) = side.str("surface") {
                        self.side_surface[k] = name.into();
                    }
                    (sw, side.num_or("end width", w)?)
                }
                None => (end, end),
            };
            (self.side_start[k], self.side_end[k]) = (sw, ew);
            if let Some(border) = seg.section(Self::BORDER[k]) {
                self.border_width[k] = border.num_or("width", self.border_width[k])?;
                if let Some(name) = border.str("surface") {
                    self.border_surface[k] = name.into();
                }
                self.border_style(k, border)?;
            }
        }
        Ok(())
    }

    /// Side `k`'s verge at the fraction `t` of the segment; surfaces are looked up only where
    /// their width is positive (an unused default `grass` needs no definition).
    fn verge(
        &self,
        k: usize,
        t: f64,
        surface: &mut dyn FnMut(&str) -> Result<Surface>,
    ) -> Result<Verge> {
        let side_width =
            (self.side_start[k] + t * (self.side_end[k] - self.side_start[k])).max(0.0);
        let border_width = self.border_width[k].max(0.0);
        Ok(Verge {
            border_width,
            border: if border_width > 0.0 {
                surface(&self.border_surface[k])?
            } else {
                Verge::NONE.border
            },
            kerb_height: if border_width > 0.0 && self.curb[k] {
                self.border_height[k].max(0.0)
            } else {
                0.0
            },
            side_width,
            side: if side_width > 0.0 {
                surface(&self.side_surface[k])?
            } else {
                Verge::NONE.side
            },
            barrier: true,
        })
    }
}

/// Heights and tangents carried from one segment to the next, as TORCS does.
#[derive(Debug, Default)]
struct ProfileState {
    /// Elevation of the left and right edges at the end of the previous segment.
    zel: f64,
    zer: f64,
    /// End tangents of the left and right profiles (dz/ds).
    etgtl: f64,
    etgtr: f64,
    /// The last `grade` given, if any.
    grade: Option<f64>,
    /// Version 3: `z start` / `z end` set both edges before the banking is derived.
    sides_follow_z: bool,
}

/// Cubic Hermite interpolation between heights p0, p1 with end slopes t0, t1 (scaled by the
/// segment length), at t ∈ [0, 1]: p0(2t³−3t²+1) + p1(−2t³+3t²) + t0(t³−2t²+t) + t1(t³−t²).
fn hermite(p0: f64, p1: f64, t0: f64, t1: f64, t: f64) -> f64 {
    let (t2, t3) = (t * t, t * t * t);
    p0 * (2.0 * t3 - 3.0 * t2 + 1.0)
        + p1 * (-2.0 * t3 + 3.0 * t2)
        + t0 * (t3 - 2.0 * t2 + t)
        + t1 * (t3 - t2)
}

/// The longest segment a track file may give: a whole lap of the Nürburgring's Nordschleife is
/// 21 km, so a longer segment is a mistake in the file, not a track.
const MAX_SEGMENT_LENGTH_M: f64 = 100_000.0;

fn segment_pieces(
    params: &Params,
    seg: &Section,
    width: f64,
    global_step: f64,
    road: Surface,
    st: &mut ProfileState,
    out: &mut Vec<Piece>,
) -> Result<()> {
    let err = |field: &str, msg: String| {
        params.error(
            &format!("{}/{field}", seg.path),
            Some(seg.line_of(field)),
            msg,
        )
    };
    let kind = seg
        .str("type")
        .ok_or_else(|| err("type", "missing segment type (str, lft or rgt)".into()))?;
    let (length, radius, radius_end, arc, sign) = match kind {
        "str" => {
            let lg = seg.require_num("lg")?;
            (lg, 0.0, 0.0, 0.0, 0.0)
        }
        "lft" | "rgt" => {
            let r = seg.require_num("radius")?;
            let r1 = seg.num_or("end radius", r)?;
            let arc = seg.require_num("arc")?;
            if r <= 0.0 || r1 <= 0.0 {
                return Err(err(
                    "radius",
                    format!("radii must be positive, got {r} m and {r1} m"),
                ));
            }
            if arc <= 0.0 {
                return Err(err(
                    "arc",
                    format!("arc must be positive, got {} deg", arc.to_degrees()),
                ));
            }
            (
                0.5 * (r + r1) * arc,
                r,
                r1,
                arc,
                if kind == "lft" { 1.0 } else { -1.0 },
            )
        }
        other => {
            return Err(err(
                "type",
                format!("unknown segment type {other:?} (expected str, lft or rgt)"),
            ));
        }
    };
    if !(length > 0.0 && length <= MAX_SEGMENT_LENGTH_M) {
        return Err(err(
            "lg",
            format!("length must be positive and at most 100 km, got {length} m"),
        ));
    }

    // Elevation and banking (track4.cpp, "elevation and banking").
    let mut zsl = seg.num_or("z start left", st.zel)?;
    let mut zsr = seg.num_or("z start right", st.zer)?;
    let mut zel = seg.num_or("z end left", st.zel)?;
    let mut zer = seg.num_or("z end right", st.zer)?;
    if let Some(g) = seg.num("grade")? {
        st.grade = Some(g);
    }
    let zs = match seg.num("z start")? {
        Some(z) => {
            if st.sides_follow_z {
                (zsl, zsr) = (z, z);
            }
            z
        }
        None => 0.5 * (zsl + zsr),
    };
    let ze = match (seg.num("z end")?, st.grade) {
        (Some(z), _) => {
            if st.sides_follow_z {
                (zel, zer) = (z, z);
            }
            z
        }
        (None, Some(g)) => zs + length * g,
        (None, None) => 0.5 * (zel + zer),
    };
    let bank_s = seg.num_or("banking start", (zsl - zsr).atan2(width))?;
    let bank_e = seg.num_or("banking end", (zel - zer).atan2(width))?;
    let dz = bank_s.tan() * width / 2.0;
    (zsl, zsr) = (zs + dz, zs - dz);
    let dz = bank_e.tan() * width / 2.0;
    (zel, zer) = (ze + dz, ze - dz);

    // Profile (track4.cpp, "get segment profil").
    let spline = seg.str("profil").unwrap_or("spline") == "spline";
    let (steps, stgtl, etgtl, stgtr, etgtr);
    if spline {
        let mut n = seg.num_or("profil steps", 1.0)? as usize;
        if n <= 1 {
            let step_len = seg.num_or("profil steps length", global_step)?;
            n = if step_len > 0.0 {
                ((length / step_len) as usize).saturating_add(1)
            } else {
                1
            };
        }
        steps = n.clamp(1, 100_000);
        // A common tangent overrides the left / right ones, which default to the previous end.
        let tangent = |common: &str, side: &str, carried: f64| -> Result<f64> {
            match seg.num(common)? {
                Some(t) => Ok(t),
                None => seg.num_or(&format!("{common} {side}"), carried),
            }
        };
        stgtl = tangent("profil start tangent", "left", st.etgtl)?;
        stgtr = tangent("profil start tangent", "right", st.etgtr)?;
        etgtl = tangent("profil end tangent", "left", st.etgtl)?;
        etgtr = tangent("profil end tangent", "right", st.etgtr)?;
    } else {
        steps = 1;
        stgtl = (zel - zsl) / length;
        etgtl = stgtl;
        stgtr = (zer - zsr) / length;
        etgtr = stgtr;
    }
    (st.zel, st.zer, st.etgtl, st.etgtr) = (zel, zer, etgtl, etgtr);

    // Sub-segment lengths and radii (track4.cpp, "Compute the correct curLength").
    let mut cur_length = length / steps as f64;
    let mut dradius = (radius_end - radius) / steps as f64;
    if radius_end != radius && steps != 1 {
        dradius = (radius_end - radius) / (steps - 1) as f64;
        let turned: f64 = (0..steps)
            .map(|i| cur_length / (radius + i as f64 * dradius))
            .sum();
        cur_length *= arc / turned;
    }
    let (t1l, t2l, t1r, t2r) = (
        stgtl * length,
        etgtl * length,
        stgtr * length,
        etgtr * length,
    );
    let mut r = radius;
    let (mut zl0, mut zr0) = (zsl, zsr);
    for i in 0..steps {
        let t = (i + 1) as f64 / steps as f64;
        let zl1 = hermite(zsl, zel, t1l, t2l, t);
        let zr1 = hermite(zsr, zer, t1r, t2r, t);
        let curvature = if sign == 0.0 {
            0.0
        } else if dradius != 0.0 {
            sign / r
        } else {
            // Constant radius: each step turns arc/steps exactly.
            sign * (arc / steps as f64) / cur_length
        };
        out.push(Piece {
            length: cur_length,
            curvature,
            z0: 0.5 * (zl0 + zr0),
            z1: 0.5 * (zl1 + zr1),
            banking0: (zl0 - zr0).atan2(width),
            banking1: (zl1 - zr1).atan2(width),
            width,
            friction: road.friction,
            rolling_resistance: road.rolling_resistance,
            roughness: road.roughness,
            verges: [Verge::NONE; 2],
        });
        (zl0, zr0) = (zl1, zr1);
        if sign != 0.0 {
            r += dradius;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
