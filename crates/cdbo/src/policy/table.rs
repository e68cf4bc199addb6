//! A policy as an (x, a) table, linear between points: the form a real car's controller
//! loads, and what `cdbo lap --policy FILE.csv` drives.

use std::path::Path;

use crate::bounded;
use crate::drive::{Observation, Pedal};
use crate::error::{Error, Result};

/// Points (xᵢ, aᵢ) with increasing x; π(x) is linear in between and constant beyond the ends.
#[derive(Debug, Clone, PartialEq)]
pub struct PolicyTable {
    points: Vec<(f64, f64)>,
}

impl PolicyTable {
    /// A table from points; x must increase strictly and a lie in [−1, 1].
    pub fn new(points: Vec<(f64, f64)>) -> Result<PolicyTable> {
        if points.is_empty() {
            return Err(Error::too_small("policy table points", 0, 1));
        }
        for (i, &(x, a)) in points.iter().enumerate() {
            if !x.is_finite() || !a.is_finite() || !(-1.0..=1.0).contains(&a) {
                return Err(Error::invalid_value(
                    format!("policy point {i}"),
                    format!("(x {x}, a {a})"),
                    "finite with a in [-1, 1]",
                ));
            }
            if i > 0 && x <= points[i - 1].0 {
                return Err(Error::invalid_value(
                    format!("policy point {i}'s x"),
                    x,
                    format!("above the previous point's {}", points[i - 1].0),
                ));
            }
        }
        Ok(PolicyTable { points })
    }

    /// Reads `x,a` rows (a header line and `#` comments are skipped).
    pub fn read_csv(path: &Path) -> Result<PolicyTable> {
        let text = bounded::read_text(path, &bounded::POLICY_TABLE)?;
        PolicyTable::parse_csv(&text, &path.display().to_string())
    }

    /// Parses `x,a` rows; `file` names the text in errors.
    pub fn parse_csv(text: &str, file: &str) -> Result<PolicyTable> {
        let mut points = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty()
                || line.starts_with('#')
                || (i == 0 && line.chars().next().is_some_and(char::is_alphabetic))
            {
                continue;
            }
            let err = |m: String| Error::Parse {
                file: file.to_owned(),
                line: Some(i as u32 + 1),
                element: "row".into(),
                message: m,
            };
            let cols: Vec<&str> = line.split(',').map(str::trim).collect();
            if cols.len() != 2 {
                return Err(err(format!("expected 2 columns x,a, found {}", cols.len())));
            }
            let num = |s: &str| {
                s.parse::<f64>()
                    .map_err(|_| err(format!("{s:?} is not a number")))
            };
            points.push((num(cols[0])?, num(cols[1])?));
        }
        PolicyTable::new(points).map_err(|e| Error::parse(file, "rows", e.to_string()))
    }

    /// The points (xᵢ, aᵢ).
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// π(x).
    pub fn action(&self, x: f64) -> f64 {
        crate::interp::linear(&self.points, x)
    }
}

impl Pedal for PolicyTable {
    fn pedal(&mut self, obs: &Observation) -> f64 {
        self.action(obs.x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_linearly_and_holds_the_ends() {
        let t = PolicyTable::new(vec![(0.0, -1.0), (0.5, 1.0), (1.0, 0.0)]).unwrap();
        assert_eq!(t.action(-0.1), -1.0);
        assert_eq!(t.action(0.25), 0.0);
        assert_eq!(t.action(0.75), 0.5);
        assert_eq!(t.action(2.0), 0.0);
    }

    #[test]
    fn rejects_bad_points() {
        assert!(PolicyTable::new(vec![]).is_err());
        assert!(PolicyTable::new(vec![(0.0, 2.0)]).is_err());
        assert!(PolicyTable::new(vec![(0.5, 0.0), (0.5, 0.1)]).is_err());
        assert!(PolicyTable::new(vec![(f64::NAN, 0.0)]).is_err());
    }
}
