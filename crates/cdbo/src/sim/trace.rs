//! A lap's trace: one row per driver step, as `cdbo lap --trace` writes it and the game's robot
//! (`torcs-robot/cdbo.cpp`) writes it too, in the columns of [`HEADER`]; [`parse`] reads it
//! back ([`crate::sim::log`] reads any real car's log, whose columns may be fewer).

use std::io::Write;
use std::path::Path;

use serde::Serialize;

use crate::bounded;
use crate::error::{Error, Result};

/// One driver step of a lap, recorded when a trace is asked for.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TracePoint {
    /// Time (s).
    pub t: f64,
    /// Distance covered along the centre line (m).
    pub distance_m: f64,
    /// Lap fraction x.
    pub x: f64,
    /// Speed (m/s).
    pub speed: f64,
    /// Pedal command a ∈ [−1, 1].
    pub pedal: f64,
    /// Steering angle (rad).
    pub steer: f64,
    /// Offset from the centre line (m), positive left.
    pub lateral: f64,
    /// Angle between the car's heading and the centre line's (rad).
    pub heading_error: f64,
    /// Body slip angle atan(v_y / vₓ) (rad).
    pub slip_angle: f64,
    /// Gear (1 = first).
    pub gear: usize,
    /// Engine speed (rpm).
    pub rpm: f64,
    /// Position (m).
    pub pos_x: f64,
    /// Position (m).
    pub pos_y: f64,
    /// Yaw rate (rad/s, positive turning left).
    pub yaw_rate: f64,
    /// The wheels' speeds ω·R (m/s): the front axle's, the rear left's, the rear right's.
    pub wheel_speeds: [f64; 3],
}

/// The trace's header, its columns in [`TracePoint`]'s order.
pub const HEADER: &str = "t_s,distance_m,x,speed_mps,pedal,steer_rad,lateral_m,heading_error_rad,slip_angle_rad,gear,rpm,pos_x_m,pos_y_m,yaw_rate_rad_s,wheel_speed_front_mps,wheel_speed_rear_left_mps,wheel_speed_rear_right_mps";

/// The number of columns in [`HEADER`].
pub const COLUMNS: usize = 17;

/// Each column's decimals as written, those of the robot's `fprintf`.
const DECIMALS: [usize; COLUMNS] = [3, 3, 6, 4, 4, 5, 4, 5, 5, 0, 0, 3, 3, 5, 4, 4, 4];

impl TracePoint {
    /// The point's values in [`HEADER`]'s columns.
    pub fn values(&self) -> [f64; COLUMNS] {
        let [front, rear_left, rear_right] = self.wheel_speeds;
        [
            self.t,
            self.distance_m,
            self.x,
            self.speed,
            self.pedal,
            self.steer,
            self.lateral,
            self.heading_error,
            self.slip_angle,
            self.gear as f64,
            self.rpm,
            self.pos_x,
            self.pos_y,
            self.yaw_rate,
            front,
            rear_left,
            rear_right,
        ]
    }

    /// The point of [`HEADER`]'s columns' values (a reverse gear, below 0, read as 0).
    fn of_values(v: [f64; COLUMNS]) -> TracePoint {
        TracePoint {
            t: v[0],
            distance_m: v[1],
            x: v[2],
            speed: v[3],
            pedal: v[4],
            steer: v[5],
            lateral: v[6],
            heading_error: v[7],
            slip_angle: v[8],
            gear: v[9].max(0.0) as usize,
            rpm: v[10],
            pos_x: v[11],
            pos_y: v[12],
            yaw_rate: v[13],
            wheel_speeds: [v[14], v[15], v[16]],
        }
    }
}

/// Writes `trace` under [`HEADER`], each value to the decimals the robot writes it with.
pub fn write(w: &mut impl Write, trace: &[TracePoint]) -> std::io::Result<()> {
    writeln!(w, "{HEADER}")?;
    for p in trace {
        for (k, v) in p.values().iter().enumerate() {
            let comma = if k == 0 { "" } else { "," };
            write!(w, "{comma}{v:.*}", DECIMALS[k])?;
        }
        writeln!(w)?;
    }
    Ok(())
}

/// Reads a trace file ([`parse`]), at most [`bounded::TRACE_FILE`] long.
pub fn read(path: &Path) -> Result<Vec<TracePoint>> {
    let text = bounded::read_text(path, &bounded::TRACE_FILE)?;
    parse(&text, &path.display().to_string())
}

/// Parses a trace: [`HEADER`], then rows of 17 finite numbers (a reverse gear, below 0, read
/// as 0). `file` names it in errors, each with its line and column.
pub fn parse(text: &str, file: &str) -> Result<Vec<TracePoint>> {
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default().trim();
    if header != HEADER {
        return Err(Error::Parse {
            file: file.into(),
            line: Some(1),
            element: "header".into(),
            message: format!(
                "expected the header of `cdbo lap --trace` ({HEADER}), found {header:?}"
            ),
        });
    }
    let names: Vec<&str> = HEADER.split(',').collect();
    let mut points = Vec::new();
    for (i, line) in lines.enumerate() {
        let bad = |element: &str, message: String| Error::Parse {
            file: file.into(),
            line: Some(i as u32 + 2),
            element: element.into(),
            message,
        };
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != COLUMNS {
            return Err(bad(
                "row",
                format!("expected {COLUMNS} columns, found {}", cells.len()),
            ));
        }
        let mut v = [0.0; COLUMNS];
        for (k, cell) in cells.iter().enumerate() {
            v[k] = cell
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(names[k], format!("{cell:?} is not a finite number")))?;
        }
        points.push(TracePoint::of_values(v));
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(k: f64) -> TracePoint {
        TracePoint {
            t: 0.02 * k,
            distance_m: 0.3 * k,
            x: 0.001 * k,
            speed: 15.0 + k,
            pedal: -0.25,
            steer: 0.0125,
            lateral: -1.5,
            heading_error: 0.01,
            slip_angle: -0.002,
            gear: 2,
            rpm: 4200.0,
            pos_x: 100.0 + k,
            pos_y: -50.0,
            yaw_rate: 0.125,
            wheel_speeds: [15.0, 15.5, 14.5],
        }
    }

    /// What [`write`] writes, [`parse`] reads back: the same points, to the written precision
    /// (these values are exact in it).
    #[test]
    fn a_written_trace_reads_back() {
        let trace = [point(0.0), point(1.0), point(2.0)];
        let mut text = Vec::new();
        write(&mut text, &trace).unwrap();
        let text = String::from_utf8(text).unwrap();
        assert_eq!(text.lines().next(), Some(HEADER));
        assert_eq!(HEADER.split(',').count(), COLUMNS);
        assert_eq!(parse(&text, "lap.csv").unwrap(), trace);
    }

    /// Another header, a short row, a cell that is not a finite number: an error naming the
    /// file, the line and the column.
    #[test]
    fn a_bad_trace_is_named_where_it_is_bad() {
        let mut good = Vec::new();
        write(&mut good, &[point(0.0)]).unwrap();
        let good = String::from_utf8(good).unwrap();
        let row = good.lines().nth(1).unwrap();
        let cases = [
            ("t_s,speed_mps\n1,2\n".to_string(), "lap.csv:1: header"),
            (
                format!("{HEADER}\n1,2,3\n"),
                "lap.csv:2: row: expected 17 columns, found 3",
            ),
            (
                format!("{HEADER}\n{row}\n{}\n", row.replacen("15.0000", "NaN", 1)),
                "lap.csv:3: speed_mps: \"NaN\" is not a finite number",
            ),
        ];
        for (text, expected) in cases {
            let error = parse(&text, "lap.csv").unwrap_err().to_string();
            assert!(error.contains(expected), "{error}");
        }
        assert_eq!(parse(HEADER, "lap.csv").unwrap(), vec![]);
    }
}
