//! A calibrated car: a base car and six scales over its uncertain parameters, as
//! `cdbo torcs calibrate` fits them (crate::calibrate) and writes them.
//!
//! The file (`.toml`, loaded wherever `--car` takes a car) is an overlay, not a copy, so that
//! it stays readable and tied to the car it was fitted for:
//!
//! ```toml
//! base = "car1-trb1"       # any car --car takes but another calibration
//! [scales]
//! grip = 0.97              # tyre μ (both axles)
//! peak_slip = 1.10         # the slip at which the tyre's force peaks (stiffness / scale)
//! drag = 1.04              # aerodynamic drag, body and wings
//! downforce = 0.90         # aerodynamic downforce, body and wings
//! rolling = 1.00           # rolling resistance (the road's coefficient, or the tyres')
//! launch = 0.80            # drive torque in first gear
//! ```
//!
//! Why these six: the demonstrations agree within 0.79 % on the 38 installed tracks (docs/results/torcs.md), so what
//! is left between cdbo's simulator and the game (or a real car) is in what the car file
//! does not pin down: the tyre's grip and shape, the aerodynamic maps (simuv2's body downforce
//! depends on ride height), the surface's rolling resistance, and the launch (the robot's
//! clutch slips through first gear and simuv2's tyre has no slip floor). Missing scales are 1;
//! a stock car (all six 1) simulates bit for bit as its base: every scale is a multiplication
//! by 1 there.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::Car;
use crate::error::{Error, Result};

/// Scales over a car's uncertain parameters; 1 leaves the car as its file gives it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scales {
    /// Tyre peak friction μ, both axles.
    pub grip: f64,
    /// The slip at which the tyre's force peaks: the Magic-Formula stiffness B·C is divided
    /// by it (the shape is a function of B·s, so its peak moves by exactly this factor).
    pub peak_slip: f64,
    /// Aerodynamic drag (body and wings).
    pub drag: f64,
    /// Aerodynamic downforce (body and wings).
    pub downforce: f64,
    /// Rolling resistance (the road surface's coefficient where the track has one).
    pub rolling: f64,
    /// Drive torque at the wheels in first gear.
    pub launch: f64,
}

impl Default for Scales {
    fn default() -> Self {
        Scales::ONE
    }
}

impl Scales {
    /// The stock car: every scale 1.
    pub const ONE: Scales = Scales {
        grip: 1.0,
        peak_slip: 1.0,
        drag: 1.0,
        downforce: 1.0,
        rolling: 1.0,
        launch: 1.0,
    };

    /// The scales' names, in the order of [`Scales::get`] / [`Scales::set`].
    pub const NAMES: [&'static str; 6] = [
        "grip",
        "peak_slip",
        "drag",
        "downforce",
        "rolling",
        "launch",
    ];

    /// The range a fit and a file may take each scale in, in [`Scales::NAMES`] order: wide
    /// enough for any car file that is roughly right (grip ±30 %, aero and rolling by 2-5×),
    /// narrow enough that the simulator stays meaningful.
    pub const BOUNDS: [(f64, f64); 6] = [
        (0.7, 1.3),
        (0.5, 2.0),
        (0.5, 2.0),
        (0.3, 3.0),
        (0.2, 5.0),
        (0.3, 1.5),
    ];

    /// The scale of index `i` ([`Scales::NAMES`]).
    pub fn get(&self, i: usize) -> f64 {
        [
            self.grip,
            self.peak_slip,
            self.drag,
            self.downforce,
            self.rolling,
            self.launch,
        ][i]
    }

    /// Sets the scale of index `i` ([`Scales::NAMES`]).
    pub fn set(&mut self, i: usize, v: f64) {
        *[
            &mut self.grip,
            &mut self.peak_slip,
            &mut self.drag,
            &mut self.downforce,
            &mut self.rolling,
            &mut self.launch,
        ][i] = v;
    }

    /// The index of the scale called `name`.
    pub fn index(name: &str) -> Option<usize> {
        Scales::NAMES.iter().position(|n| *n == name)
    }

    /// Checks every scale lies within its [`Scales::BOUNDS`].
    pub fn check(&self) -> std::result::Result<(), String> {
        for (i, name) in Scales::NAMES.iter().enumerate() {
            let (lo, hi) = Scales::BOUNDS[i];
            let v = self.get(i);
            if !(lo..=hi).contains(&v) {
                return Err(format!("{name} = {v}: must be within [{lo}, {hi}]"));
            }
        }
        Ok(())
    }

    /// `base` with these scales: grip and peak slip go into its tyres (μ·grip, stiffness /
    /// peak_slip), the other four are kept in [`Car::scales`] and applied where the forces
    /// are computed ([`Car::drag`], [`Car::downforce`], [`crate::vehicle`]).
    pub fn apply(&self, base: &Car) -> Car {
        let mut car = base.clone();
        for tyre in [&mut car.front_tyre, &mut car.rear_tyre] {
            tyre.mu *= self.grip;
            tyre.stiffness /= self.peak_slip;
        }
        car.scales = Scales {
            grip: base.scales.grip * self.grip,
            peak_slip: base.scales.peak_slip * self.peak_slip,
            drag: base.scales.drag * self.drag,
            downforce: base.scales.downforce * self.downforce,
            rolling: base.scales.rolling * self.rolling,
            launch: base.scales.launch * self.launch,
        };
        car
    }
}

/// A calibrated car file: its base car and its scales.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// The base car: a name or a car file `--car` takes (not another calibration).
    pub base: String,
    /// The scales over it.
    #[serde(default)]
    pub scales: Scales,
}

impl Calibration {
    /// Parses a calibration's TOML; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Calibration> {
        let c: Calibration =
            toml::from_str(text).map_err(|e| Error::parse(file, "calibration", one_line(&e)))?;
        c.scales
            .check()
            .map_err(|m| Error::parse(file, "scales", m))?;
        if c.base.ends_with(".toml") {
            return Err(Error::parse(
                file,
                "base",
                format!(
                    "{:?}: the base must be a car, not another calibration",
                    c.base
                ),
            ));
        }
        Ok(c)
    }

    /// The file's text: a comment line, then `base` and `[scales]`.
    pub fn to_toml(&self, comment: &str) -> String {
        let mut s = String::new();
        for line in comment.lines() {
            s.push_str(&format!("# {line}\n"));
        }
        s.push_str(&toml::to_string(self).unwrap_or_default());
        s
    }
}

/// A TOML error on one line.
fn one_line(e: &toml::de::Error) -> String {
    e.to_string()
        .lines()
        .filter(|l| !l.trim().is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Reads a calibrated car file: its base, found by `find_base` (as `--car` finds a car,
/// [`super::catalog::find`]), with its scales.
pub fn read(path: &Path, find_base: &dyn Fn(&str) -> Result<Car>) -> Result<Car> {
    let text = crate::bounded::read_text(path, &crate::bounded::CAR_FILE)?;
    let file = path.display().to_string();
    let c = Calibration::parse(&text, &file)?;
    // A relative file path as base is read beside the calibration.
    let beside = path.parent().map(|d| d.join(&c.base));
    let base = match beside.filter(|p| p.is_file()) {
        Some(p) => find_base(&p.display().to_string()),
        None => find_base(&c.base),
    }
    .map_err(|e| Error::parse(&file, "base", e.to_string()))?;
    let mut car = c.scales.apply(&base);
    car.name = format!("{} (calibrated)", base.name);
    Ok(car)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_round_trip_and_are_checked() {
        let c = Calibration {
            base: "car1-trb1".into(),
            scales: Scales {
                grip: 0.9,
                launch: 0.75,
                ..Scales::ONE
            },
        };
        let text = c.to_toml("fitted by a test");
        assert!(text.starts_with("# fitted by a test\n"), "{text}");
        assert_eq!(Calibration::parse(&text, "c.toml").unwrap(), c);
        // Missing scales are 1.
        let c = Calibration::parse("base = \"x\"\n[scales]\ngrip = 1.1\n", "c.toml").unwrap();
        assert_eq!(c.scales.drag, 1.0);
        assert_eq!(c.scales.grip, 1.1);
        let e = Calibration::parse("base = \"x\"\n[scales]\ngrip = 9\n", "c.toml").unwrap_err();
        assert_eq!(
            e.to_string(),
            "c.toml: scales: grip = 9: must be within [0.7, 1.3]"
        );
        let e = Calibration::parse("base = \"x\"\n[scales]\ngrp = 1\n", "c.toml").unwrap_err();
        assert!(e.to_string().contains("grp"), "{e}");
        let e = Calibration::parse("base = \"a.toml\"\n", "c.toml").unwrap_err();
        assert!(e.to_string().contains("not another calibration"), "{e}");
    }

    #[test]
    fn one_leaves_the_car_as_it_is() {
        let car = Car::spirit_300();
        assert_eq!(Scales::ONE.apply(&car), car);
        let s = Scales {
            grip: 1.2,
            peak_slip: 2.0,
            ..Scales::ONE
        };
        let c = s.apply(&car);
        assert_eq!(c.front_tyre.mu, car.front_tyre.mu * 1.2);
        assert_eq!(c.rear_tyre.stiffness, car.rear_tyre.stiffness / 2.0);
        assert_eq!(c.scales.grip, 1.2);
    }
}
