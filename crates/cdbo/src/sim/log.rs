//! A logged lap file for calibration (`cdbo torcs calibrate --log laps.csv`): a real car's laps,
//! or the game's as `cdbo torcs calibrate` writes them (`log_TRACK.csv`).
//!
//! CSV with a header naming the columns (any order; other columns are ignored, so a
//! `cdbo lap --trace` file is a one-lap log):
//!
//! | column | unit | required |
//! | --- | --- | --- |
//! | `distance_m` (or `x`, the lap fraction) | m along the centre line from the start line | yes |
//! | `speed_mps` | speed over ground, m/s | yes |
//! | `lateral_m` | offset from the centre line, m, positive left | yes |
//! | `yaw_rate_rad_s` | yaw rate, rad/s, positive turning left | yes |
//! | `pedal` | the pedal command applied, −1 (full brake) … 1 (full throttle) | yes |
//! | `steer_rad` | the road-wheel steering angle applied, rad | no (not fitted; [`crate::sim::replay`] needs it) |
//! | `slip_angle_rad` | the body's slip angle atan(v_y/v_x), rad | no (replay: 0 without it) |
//! | `gear` | the gear engaged, 1 = first (0 = neutral) | no (replay: cdbo's gearbox without it) |
//! | `wheel_speed_front_mps`, `wheel_speed_rear_left_mps`, `wheel_speed_rear_right_mps` | the wheels' speeds ω·R, m/s (the front axle's mean) | no, all three or none (replay: the wheels rolling at vₓ without them) |
//! | `t_s` | time since the start, s (gives the lap time of a completed lap) | no (replay needs it) |
//! | `lap` | a lap number: rows of one lap are consecutive | no (one lap) |
//!
//! Each lap starts standing on the start line, as cdbo's laps do. A lap is complete when it
//! reaches within 1 % of the track's length. Refused, in one line naming the file, line and
//! column: a missing column, a cell that is not a finite number, a pedal outside [−1, 1], a
//! station outside the track (below −5 m, or beyond its length by more than 2 % — a log of
//! another track), a lap that runs back more than 10 m, or a lap of fewer than 2 rows.

use crate::error::{Error, Result};

/// One logged sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Distance along the centre line from the start line (m).
    pub distance_m: f64,
    /// Speed (m/s).
    pub speed: f64,
    /// Offset from the centre line (m), positive left.
    pub lateral: f64,
    /// Yaw rate (rad/s).
    pub yaw_rate: f64,
    /// Pedal command applied, in [−1, 1].
    pub pedal: f64,
    /// Time since the start (s), when logged.
    pub t: Option<f64>,
    /// Road-wheel steering angle applied (rad), when logged.
    pub steer: Option<f64>,
    /// Body slip angle (rad), when logged.
    pub slip_angle: Option<f64>,
    /// Gear engaged (1 = first, 0 = neutral), when logged.
    pub gear: Option<u8>,
    /// The wheels' speeds ω·R (m/s): the front axle's, the rear left's, the rear right's,
    /// when logged.
    pub wheel_speeds: Option<[f64; 3]>,
}

impl Sample {
    /// A step of a traced lap ([`crate::sim::lap`]), as a log's row.
    pub fn of(p: &crate::sim::TracePoint) -> Sample {
        Sample {
            distance_m: p.distance_m,
            speed: p.speed,
            lateral: p.lateral,
            yaw_rate: p.yaw_rate,
            pedal: p.pedal,
            t: Some(p.t),
            steer: Some(p.steer),
            slip_angle: Some(p.slip_angle),
            gear: u8::try_from(p.gear).ok(),
            wheel_speeds: Some(p.wheel_speeds),
        }
    }
}

/// One logged lap.
#[derive(Debug, Clone, PartialEq)]
pub struct LoggedLap {
    /// Its number in the file (the `lap` column, else 0).
    pub lap: i64,
    /// The 1-based line of its first row.
    pub line: usize,
    /// Its samples, in the order logged.
    pub samples: Vec<Sample>,
}

impl LoggedLap {
    /// The farthest distance reached (m).
    pub fn end_m(&self) -> f64 {
        self.samples
            .iter()
            .map(|s| s.distance_m)
            .fold(0.0, f64::max)
    }

    /// Whether the lap reached within 1 % of a track of `length` metres.
    pub fn completed(&self, length: f64) -> bool {
        self.end_m() >= COMPLETE_FRACTION * length
    }

    /// The lap time (s) of a completed lap with a time column: the time of its last row.
    pub fn lap_time_s(&self, length: f64) -> Option<f64> {
        if !self.completed(length) {
            return None;
        }
        self.samples.last().and_then(|s| s.t)
    }

    /// The pedal applied along the lap, (x, a) with x strictly increasing: the open-loop
    /// table cdbo's simulator replays.
    pub fn pedal_table(&self, length: f64) -> Vec<(f64, f64)> {
        let mut points: Vec<(f64, f64)> = Vec::with_capacity(self.samples.len());
        for s in &self.samples {
            let x = (s.distance_m / length).clamp(0.0, 1.0);
            match points.last() {
                Some(&(last, _)) if x <= last => {}
                _ => points.push((x, s.pedal)),
            }
        }
        points
    }
}

/// A lap reaching this fraction of the track's length counts as complete.
pub const COMPLETE_FRACTION: f64 = 0.99;
/// How far a station may lie beyond the track's length before the log is refused, as a
/// fraction of it.
pub const BEYOND_FRACTION: f64 = 0.02;
/// How far before the start line a station may lie (m).
pub const BEFORE_START_M: f64 = 5.0;
/// How far a lap may run back (m) before the log is refused.
pub const BACK_M: f64 = 10.0;

/// The columns read, by header name.
const DISTANCE: &str = "distance_m";
const FRACTION: &str = "x";
const SPEED: &str = "speed_mps";
const LATERAL: &str = "lateral_m";
const YAW_RATE: &str = "yaw_rate_rad_s";
const PEDAL: &str = "pedal";
const TIME: &str = "t_s";
const LAP: &str = "lap";
const STEER: &str = "steer_rad";
const SLIP_ANGLE: &str = "slip_angle_rad";
const GEAR: &str = "gear";
const WHEEL_SPEEDS: [&str; 3] = [
    "wheel_speed_front_mps",
    "wheel_speed_rear_left_mps",
    "wheel_speed_rear_right_mps",
];
/// The highest gear a log may name.
pub const MAX_GEAR: u8 = 12;

/// Parses a log of laps on a track of `length` metres; `file` names it in errors.
pub fn parse(text: &str, file: &str, length: f64) -> Result<Vec<LoggedLap>> {
    let err = |line: usize, column: &str, message: String| Error::Parse {
        file: file.to_owned(),
        line: Some(line as u32),
        element: if column.is_empty() {
            "row".to_owned()
        } else {
            format!("column {column}")
        },
        message,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((header_line, header)) = lines.next() else {
        return Err(Error::parse(file, "header", "the log is empty"));
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let find = |name: &str| names.iter().position(|n| *n == name);
    let required = |name: &str| {
        find(name).ok_or_else(|| {
            err(
                header_line,
                name,
                format!(
                    "missing: the header names {} (required: {DISTANCE} or {FRACTION}, {SPEED}, {LATERAL}, {YAW_RATE}, {PEDAL})",
                    names.join(",")
                ),
            )
        })
    };
    let (station, in_metres) = match (find(DISTANCE), find(FRACTION)) {
        (Some(i), _) => (i, true),
        (None, Some(i)) => (i, false),
        (None, None) => return Err(required(DISTANCE).unwrap_err()),
    };
    let speed = required(SPEED)?;
    let lateral = required(LATERAL)?;
    let yaw_rate = required(YAW_RATE)?;
    let pedal = required(PEDAL)?;
    let (time, lap_col) = (find(TIME), find(LAP));
    let (steer, slip_angle, gear) = (find(STEER), find(SLIP_ANGLE), find(GEAR));
    let wheel_speeds = match WHEEL_SPEEDS.map(find) {
        [Some(f), Some(l), Some(r)] => Some([f, l, r]),
        [None, None, None] => None,
        found => {
            let missing = WHEEL_SPEEDS
                .iter()
                .zip(found)
                .find_map(|(name, i)| i.is_none().then_some(*name))
                .unwrap_or_default();
            return Err(err(
                header_line,
                missing,
                format!(
                    "missing: the wheels' speeds come as all of {} or none",
                    WHEEL_SPEEDS.join(", ")
                ),
            ));
        }
    };

    let mut laps: Vec<LoggedLap> = Vec::new();
    for (line, row) in lines {
        let cells: Vec<&str> = row.split(',').map(str::trim).collect();
        if cells.len() != names.len() {
            return Err(err(
                line,
                "",
                format!(
                    "{} cells where the header names {} columns",
                    cells.len(),
                    names.len()
                ),
            ));
        }
        let num = |i: usize| -> Result<f64> {
            let c = cells[i];
            let v: f64 = c
                .parse()
                .map_err(|_| err(line, names[i], format!("{c:?} is not a number")))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(err(line, names[i], format!("{c:?} is not a finite number")))
            }
        };
        let s = num(station)?;
        let distance_m = if in_metres { s } else { s * length };
        let beyond = length * (1.0 + BEYOND_FRACTION);
        if distance_m < -BEFORE_START_M || distance_m > beyond {
            return Err(err(
                line,
                names[station],
                format!("{s} lies outside the track (0 … {length:.1} m): a log of another track?"),
            ));
        }
        let a = num(pedal)?;
        if !(-1.0..=1.0).contains(&a) {
            return Err(err(
                line,
                PEDAL,
                format!("{a} is outside [-1, 1] (1 = full throttle, -1 = full brake)"),
            ));
        }
        let sample = Sample {
            distance_m,
            speed: num(speed)?,
            lateral: num(lateral)?,
            yaw_rate: num(yaw_rate)?,
            pedal: a,
            t: time.map(num).transpose()?,
            steer: steer.map(num).transpose()?,
            slip_angle: slip_angle.map(num).transpose()?,
            gear: match gear {
                Some(i) => {
                    let g = num(i)?;
                    if g.fract() != 0.0 || !(0.0..=f64::from(MAX_GEAR)).contains(&g) {
                        return Err(err(
                            line,
                            GEAR,
                            format!("{g} is not a gear (a whole number 0 … {MAX_GEAR})"),
                        ));
                    }
                    Some(g as u8)
                }
                None => None,
            },
            wheel_speeds: match wheel_speeds {
                Some([f, l, r]) => Some([num(f)?, num(l)?, num(r)?]),
                None => None,
            },
        };
        let lap = match lap_col {
            Some(i) => {
                let v = num(i)?;
                if v.fract() != 0.0 || v.abs() > 1e15 {
                    return Err(err(line, LAP, format!("{v} is not a whole number")));
                }
                v as i64
            }
            None => 0,
        };
        match laps.last_mut() {
            Some(last) if last.lap == lap => {
                let farthest = last.end_m();
                if distance_m < farthest - BACK_M {
                    return Err(err(
                        line,
                        names[station],
                        format!(
                            "the lap runs back from {farthest:.1} m to {distance_m:.1} m (a new lap needs its own `lap` number)"
                        ),
                    ));
                }
                last.samples.push(sample);
            }
            _ => laps.push(LoggedLap {
                lap,
                line,
                samples: vec![sample],
            }),
        }
    }
    if laps.is_empty() {
        return Err(Error::parse(
            file,
            "rows",
            "the log has a header but no rows",
        ));
    }
    if let Some(short) = laps.iter().find(|l| l.samples.len() < 2) {
        return Err(err(
            short.line,
            "",
            format!("lap {} has a single row; a lap needs at least 2", short.lap),
        ));
    }
    Ok(laps)
}

/// Writes laps in the log format [`parse`] reads: every column, the lap numbered; the steering,
/// slip angle and gear where every sample has them.
pub fn write(laps: &[LoggedLap]) -> String {
    let all = |f: fn(&Sample) -> bool| laps.iter().flat_map(|l| &l.samples).all(f);
    let (steer, slip, gear) = (
        all(|p| p.steer.is_some()),
        all(|p| p.slip_angle.is_some()),
        all(|p| p.gear.is_some()),
    );
    let mut s = format!("{LAP},{DISTANCE},{SPEED},{LATERAL},{YAW_RATE},{PEDAL},{TIME}");
    for (on, name) in [(steer, STEER), (slip, SLIP_ANGLE), (gear, GEAR)] {
        if on {
            s.push(',');
            s.push_str(name);
        }
    }
    s.push('\n');
    for lap in laps {
        for p in &lap.samples {
            s.push_str(&format!(
                "{},{:.3},{:.4},{:.4},{:.5},{:.4},{}",
                lap.lap,
                p.distance_m,
                p.speed,
                p.lateral,
                p.yaw_rate,
                p.pedal,
                p.t.map_or("0".into(), |t| format!("{t:.3}"))
            ));
            if let (true, Some(v)) = (steer, p.steer) {
                s.push_str(&format!(",{v:.5}"));
            }
            if let (true, Some(v)) = (slip, p.slip_angle) {
                s.push_str(&format!(",{v:.5}"));
            }
            if let (true, Some(g)) = (gear, p.gear) {
                s.push_str(&format!(",{g}"));
            }
            s.push('\n');
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "lap,distance_m,speed_mps,lateral_m,yaw_rate_rad_s,pedal,t_s\n";

    #[test]
    fn a_log_round_trips_and_splits_into_laps() {
        let text = format!(
            "{HEAD}0,0,0,0,0,1,0\n0,50,10,0.1,0.01,1,5\n0,99.5,20,0,0,0.5,8\n1,0,0,0,0,1,0\n1,30,8,0,0,-1,4\n"
        );
        let laps = parse(&text, "l.csv", 100.0).unwrap();
        assert_eq!(laps.len(), 2);
        assert!(laps[0].completed(100.0) && !laps[1].completed(100.0));
        assert_eq!(laps[0].lap_time_s(100.0), Some(8.0));
        assert_eq!(laps[1].line, 5);
        assert_eq!(parse(&write(&laps), "l.csv", 100.0).unwrap(), laps);
        // The commands and the gear, where every sample has them, round-trip too.
        let steered = parse(
            "t_s,distance_m,speed_mps,lateral_m,yaw_rate_rad_s,pedal,steer_rad,gear\n0,0,0,0,0,1,0.01,1\n1,5,10,0,0,1,-0.02,2\n",
            "l.csv",
            100.0,
        )
        .unwrap();
        assert_eq!(steered[0].samples[1].steer, Some(-0.02));
        assert_eq!(steered[0].samples[1].gear, Some(2));
        assert_eq!(steered[0].samples[1].slip_angle, None);
        assert_eq!(parse(&write(&steered), "l.csv", 100.0).unwrap(), steered);
        assert_eq!(
            laps[0].pedal_table(100.0),
            vec![(0.0, 1.0), (0.5, 1.0), (0.995, 0.5)]
        );
    }

    #[test]
    fn bad_logs_name_file_line_and_column() {
        let bad = |text: &str| parse(text, "l.csv", 100.0).unwrap_err().to_string();
        assert!(
            bad("distance_m,speed_mps,lateral_m,pedal\n0,0,0,0\n")
                .starts_with("l.csv:1: column yaw_rate_rad_s: missing"),
        );
        assert_eq!(
            bad(&format!("{HEAD}0,0,0,0,0,1,0\n0,10,NaN,0,0,1,1\n")),
            "l.csv:3: column speed_mps: \"NaN\" is not a finite number"
        );
        assert_eq!(
            bad(&format!("{HEAD}0,0,0,0,0,1,0\n0,10,x,0,0,1,1\n")),
            "l.csv:3: column speed_mps: \"x\" is not a number"
        );
        assert_eq!(
            bad(&format!("{HEAD}0,0,0,0,0,1,0\n0,150,1,0,0,1,1\n")),
            "l.csv:3: column distance_m: 150 lies outside the track (0 … 100.0 m): a log of another track?"
        );
        assert!(bad(&format!("{HEAD}0,0,0,0,0,2,0\n")).starts_with("l.csv:2: column pedal:"));
        assert!(bad(&format!("{HEAD}0,0,0,0,0\n")).starts_with("l.csv:2: row: 5 cells"));
        assert!(
            bad(&format!("{HEAD}0,50,0,0,0,1,0\n0,20,0,0,0,1,0\n"))
                .starts_with("l.csv:3: column distance_m: the lap runs back")
        );
        assert!(bad(&format!("{HEAD}0,0,0,0,0,1,0\n")).contains("single row"));
        assert_eq!(
            bad("distance_m,speed_mps,lateral_m,yaw_rate_rad_s,pedal,gear\n0,0,0,0,1,2.5\n"),
            "l.csv:2: column gear: 2.5 is not a gear (a whole number 0 … 12)"
        );
        assert_eq!(bad(""), "l.csv: header: the log is empty");
        assert_eq!(bad(HEAD), "l.csv: rows: the log has a header but no rows");
        // A lap fraction instead of metres.
        let laps = parse(
            "x,speed_mps,lateral_m,yaw_rate_rad_s,pedal\n0,0,0,0,1\n0.5,3,0,0,1\n",
            "l.csv",
            100.0,
        )
        .unwrap();
        assert_eq!(laps[0].samples[1].distance_m, 50.0);
    }

    /// The wheels' speeds come as all three columns or none, and reach the samples.
    #[test]
    fn the_wheels_speeds_come_as_three_columns_or_none() {
        let head = "distance_m,speed_mps,lateral_m,yaw_rate_rad_s,pedal";
        let laps = parse(
            &format!(
                "{head},wheel_speed_front_mps,wheel_speed_rear_left_mps,wheel_speed_rear_right_mps\n\
                 0,10,0,0,1,10,10.5,10.7\n5,11,0,0,1,11,11.4,11.6\n"
            ),
            "l.csv",
            100.0,
        )
        .unwrap();
        assert_eq!(laps[0].samples[1].wheel_speeds, Some([11.0, 11.4, 11.6]));
        let none = parse(&format!("{head}\n0,10,0,0,1\n5,11,0,0,1\n"), "l.csv", 100.0).unwrap();
        assert_eq!(none[0].samples[0].wheel_speeds, None);
        let partial = parse(
            &format!(
                "{head},wheel_speed_front_mps,wheel_speed_rear_right_mps\n0,10,0,0,1,10,10.7\n"
            ),
            "l.csv",
            100.0,
        )
        .unwrap_err()
        .to_string();
        assert!(
            partial.starts_with("l.csv:1: column wheel_speed_rear_left_mps: missing")
                && partial.contains("all of"),
            "{partial}"
        );
    }
}
