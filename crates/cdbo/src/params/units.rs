//! Units of TORCS parameter files, converted to SI as TORCS's `GfParmGetNum` does.
//!
//! A unit is a product and quotient of base tokens: `kN/m/s` = kN ÷ m ÷ s, `N.m` = N × m,
//! `kg.m2` = kg × m². A token may end in a power digit (`m2`, `cm3`). Angles become radians,
//! `rpm` becomes rad/s, `%` becomes a fraction (×0.01), every length metres.

use std::f64::consts::PI;

/// The SI factor of one base token, or `None` if the token is unknown.
fn token_factor(token: &str) -> Option<f64> {
    let f = match token {
        "" | "-" => 1.0,
        "m" | "M" => 1.0,
        "km" => 1000.0,
        "cm" => 0.01,
        "mm" => 0.001,
        "ft" | "feet" | "foot" => 0.3048,
        "in" | "inch" | "inches" => 0.0254,
        "mi" | "mile" | "miles" => 1609.344,
        "deg" | "DEG" => PI / 180.0,
        "rad" => 1.0,
        "%" => 0.01,
        "s" | "sec" => 1.0,
        "ms" => 0.001,
        "min" => 60.0,
        "h" | "hour" | "hours" => 3600.0,
        "kg" => 1.0,
        "g" => 0.001,
        "lbs" | "lb" => 0.453_592_37,
        "t" => 1000.0,
        "N" => 1.0,
        "kN" => 1000.0,
        "daN" => 10.0,
        "lbf" => 4.448_221_615_260_5,
        "Pa" => 1.0,
        "kPa" => 1000.0,
        "MPa" => 1.0e6,
        "bar" => 1.0e5,
        "psi" | "PSI" => 6_894.757_293_168,
        // TORCS's GfParmGetNum knows no litres: a value in `l` stays as written (simuv2 then
        // counts a car's fuel, in litres, as kilograms of mass).
        "l" | "L" => 1.0,
        "W" => 1.0,
        "kW" => 1000.0,
        "hp" | "HP" => 745.699_871_582_270_2,
        "PS" | "ch" => 735.498_75,
        "rpm" | "RPM" => 2.0 * PI / 60.0,
        "Hz" => 1.0,
        "kph" => 1000.0 / 3600.0,
        "mph" | "MPH" => 0.447_04,
        _ => return None,
    };
    Some(f)
}

/// The SI factor of a unit string such as `m`, `deg`, `kN/m/s`, `N.m` or `kg.m2`.
///
/// Returns `None` for a unit TORCS would not know; the caller names the element.
pub fn si_factor(unit: &str) -> Option<f64> {
    let unit = unit.trim();
    if unit.is_empty() {
        return Some(1.0);
    }
    let mut factor = 1.0;
    for (i, quotient_part) in unit.split('/').enumerate() {
        let mut part = 1.0;
        for token in quotient_part.split(['.', '*']) {
            part *= powered_token_factor(token)?;
        }
        if i == 0 {
            factor *= part
        } else {
            factor /= part
        }
    }
    Some(factor)
}

/// A base token with an optional trailing power digit (`m2`, `cm3`).
fn powered_token_factor(token: &str) -> Option<f64> {
    if let Some(f) = token_factor(token) {
        return Some(f);
    }
    // The last character, not the last byte: a unit may end in any character (`m²`).
    let (last, _) = token.char_indices().next_back()?;
    let (base, power) = token.split_at(last);
    let power: i32 = power.parse().ok()?;
    if !(2..=4).contains(&power) {
        return None;
    }
    Some(token_factor(base)?.powi(power))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1.0)
    }

    #[test]
    fn base_units_match_their_definitions() {
        assert!(close(si_factor("ft").unwrap(), 0.3048));
        assert!(close(si_factor("deg").unwrap() * 180.0, PI));
        assert!(close(si_factor("%").unwrap(), 0.01));
        assert!(close(si_factor("rpm").unwrap() * 60.0, 2.0 * PI));
        assert!(close(si_factor("").unwrap(), 1.0));
    }

    /// A fuzzer's find: a unit ending in a multi-byte character split inside it.
    #[test]
    fn a_unit_ending_in_a_multibyte_character_is_unknown_not_a_panic() {
        assert_eq!(si_factor("m²"), None);
        assert_eq!(si_factor("kg.é"), None);
        assert!(close(si_factor("kg.m2").unwrap(), 1.0));
    }

    #[test]
    fn compound_units_compose() {
        assert!(close(si_factor("kN/m/s").unwrap(), 1000.0));
        assert!(close(si_factor("N.m").unwrap(), 1.0));
        assert!(close(si_factor("kg.m2").unwrap(), 1.0));
        assert!(close(si_factor("cm2").unwrap(), 1e-4));
        assert!(close(si_factor("km/h").unwrap(), 1.0 / 3.6));
        assert!(close(si_factor("deg/s").unwrap(), PI / 180.0));
    }

    #[test]
    fn unknown_units_are_refused() {
        assert_eq!(si_factor("furlong"), None);
        assert_eq!(si_factor("m9"), None);
        assert_eq!(si_factor("kg.parsec"), None);
    }
}
