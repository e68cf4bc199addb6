//! TORCS / Speed Dreams car files: the car's XML merged over its category's XML.
//!
//! Values missing from both take TORCS's defaults; required values (mass, torque curve, gear
//! ratios) missing from both are an error naming the element.

use std::path::{Path, PathBuf};

use super::{
    Axles, Brake, Car, DEFAULT_ENGINE_BRAKE, DEFAULT_PAD_MU, Damper, DamperCurve, DiffKind,
    Differential, Drive, Ride, Tyre, Wing,
};
use crate::bounded;
use crate::error::{Error, Result};
use crate::params::{Params, Section};

/// Reads a car file and the category file it names (`Car/category`), found beside it in the
/// TORCS layout (`cars/NAME/NAME.xml` → `categories/CAT.xml`) or the Speed Dreams layout
/// (`cars/models/NAME/NAME.xml` → `cars/categories/CAT.xml`). A missing category file is an
/// error; pass `category` explicitly to choose one.
pub fn read(path: &Path, category: Option<&Path>) -> Result<Car> {
    let car = Params::read(path, &bounded::CAR_FILE)?;
    let category_path = match category {
        Some(c) => Some(c.to_owned()),
        None => match car.section("Car").and_then(|c| c.str("category")) {
            Some(cat) => Some(find_category(path, cat).ok_or_else(|| {
                Error::parse(
                    car.file.clone(),
                    "Car/category",
                    format!("category file {cat}.xml not found in ../../categories or ../../../categories/../cars/categories; pass it explicitly"),
                )
            })?),
            None => None,
        },
    };
    let merged = match category_path {
        Some(p) => {
            let mut base = Params::read(&p, &bounded::CAR_CATEGORY_FILE)?;
            base.root.merge(&car.root);
            base.root.name = car.root.name.clone();
            base.file = car.file.clone();
            base
        }
        None => car,
    };
    from_params(&merged)
}

fn find_category(car: &Path, cat: &str) -> Option<PathBuf> {
    let dir = car.parent()?;
    let file = format!("{cat}.xml");
    [
        dir.join("../../categories"),
        dir.join("../../../categories"),
        dir.join("../../../cars/categories"),
        dir.join("../categories"),
    ]
    .into_iter()
    .map(|d| d.join(&file))
    .find(|p| p.is_file())
}

/// Rolling resistance of TORCS's asphalt surfaces (`data/tracks/surfaces.xml`).
const ASPHALT_ROLLING_RESISTANCE: f64 = 0.001;

/// The game's skid factor for cdbo's robot ([`Tyre::skid`]): its `cdbo.xml` names no skill
/// level, so TORCS's race engine (`raceinit.cpp`) ranks it semi-pro, whose factor in simuv2's
/// `categories.cpp` (`simSkidFactor`) is 0.3.
pub const SKID_FACTOR: f64 = 0.3;

/// Gravity as TORCS's `tgf.h` has it (m/s²), for the wheels' static loads.
const TORCS_G: f64 = 9.80665;

/// The grip factor of a tyre's camber γ (rad), simuv2's `wheel.cpp`: 1 + 0.05·sin(−18γ)
/// (car1-trb1's −4° front: 1.048, −3° rear: 1.040).
pub fn camber_grip(camber: f64) -> f64 {
    1.0 + 0.05 * (-18.0 * camber).sin()
}

/// The car's overall width (m): `overall width`, else `body width` (the names of TORCS's
/// `car.h`), else 1.9 m.
fn car_width(car: &Section) -> Result<f64> {
    let body = car.num_or("body width", 1.9)?;
    car.num_or("overall width", body)
}

/// Builds a car from (merged) parameters.
pub fn from_params(p: &Params) -> Result<Car> {
    let empty = Section::default();
    let sec = |name: &str| p.section(name).unwrap_or(&empty);
    let car = p.require_section("Car")?;
    let positive = |s: &Section, name: &str, v: f64| -> Result<f64> {
        if v > 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(s.value_error(name, format!("must be positive, got {v}")))
        }
    };
    let non_negative = |s: &Section, name: &str, v: f64| -> Result<f64> {
        if v >= 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(s.value_error(name, format!("must be non-negative, got {v}")))
        }
    };
    let fraction = |s: &Section, name: &str, v: f64| -> Result<f64> {
        if (0.0..=1.0).contains(&v) {
            Ok(v)
        } else {
            Err(s.value_error(name, format!("must be in [0, 1], got {v}")))
        }
    };

    // simuv2 (`car.cpp`) moves the car's mass and its fuel, m = mass + fuel, the `initial
    // fuel` (litres, counted as kilograms) capped by the `fuel tank`, both 80 by default;
    // the wheels' static loads (`weight0`) and the yaw inertia take the mass alone.
    let dry_mass = positive(car, "mass", car.require_num("mass")?)?;
    let tank = car.num_or("fuel tank", 80.0)?;
    let fuel = car.num_or("initial fuel", 80.0)?.min(tank);
    if !(fuel >= 0.0 && fuel.is_finite()) {
        return Err(car.value_error("initial fuel", format!("must be non-negative, got {fuel}")));
    }
    let mass = dry_mass + fuel;
    let cg_height = positive(car, "GC height", car.num_or("GC height", 0.3)?)?;
    let front_weight = fraction(
        car,
        "front-rear weight repartition",
        car.num_or("front-rear weight repartition", 0.5)?,
    )?;
    let centring = positive(
        car,
        "mass repartition coefficient",
        car.num_or("mass repartition coefficient", 1.0)?,
    )?;
    let body_length = positive(car, "body length", car.num_or("body length", 4.7)?)?;
    let body_width = positive(car, "body width", car.num_or("body width", 1.9)?)?;
    // The wheels' static loads as simuv2 sets them (`weight0`, from the mass without fuel):
    // each tyre's `operating load` defaults to 1.2 times its wheel's.
    let right_share = |name: &str| car.num_or(name, 0.5);
    let static_wheel_load = [
        dry_mass * TORCS_G * front_weight * right_share("front right-left weight repartition")?,
        dry_mass
            * TORCS_G
            * (1.0 - front_weight)
            * right_share("rear right-left weight repartition")?,
    ];
    let (fa, ra) = (sec("Front Axle"), sec("Rear Axle"));
    let wheelbase = positive(
        fa,
        "xpos",
        fa.num_or("xpos", 1.2)? - ra.num_or("xpos", -1.4)?,
    )?;
    // simuv2's yaw inertia I_z = m₀·(w² + c²·l²)/12, as k·m·a·b with a = (1 − f)·L and
    // b = f·L, f the front axle's share of the weight.
    let yaw_inertia = dry_mass * (body_width.powi(2) + (centring * body_length).powi(2)) / 12.0;
    let yaw_inertia_factor =
        yaw_inertia / (mass * (1.0 - front_weight) * front_weight * wheelbase * wheelbase);

    let aero = sec("Aerodynamics");
    let cx = positive(aero, "Cx", aero.num_or("Cx", 0.4)?)?;
    let front_area = positive(aero, "front area", aero.num_or("front area", 2.0)?)?;
    let clift = [
        aero.num_or("front Clift", 0.0)?,
        aero.num_or("rear Clift", 0.0)?,
    ];

    // Wings: the lever rule between the axles' positions shares their downforce.
    let rear_x = ra.num_or("xpos", -1.4)?;
    let wing = |name: &str| -> Result<Wing> {
        let w = sec(name);
        let area = w.num_or("area", 0.0)?;
        if !(area >= 0.0 && area.is_finite()) {
            return Err(w.value_error("area", format!("must be non-negative, got {area}")));
        }
        Ok(Wing {
            area,
            angle: w.num_or("angle", 0.0)?,
            front_share: (w.num_or("xpos", rear_x)? - rear_x) / wheelbase,
            height: w.num_or("zpos", 0.0)?,
        })
    };
    let wings = [wing("Front Wing")?, wing("Rear Wing")?];

    let engine = p.require_section("Engine")?;
    let points = engine
        .section("data points")
        .ok_or_else(|| engine.error("Engine/data points", "missing torque curve"))?;
    let mut torque_curve = Vec::new();
    for pt in &points.sections {
        let w = pt.require_num("rpm")?;
        let t = pt.require_num("Tq")?;
        if let Some(&(w0, _)) = torque_curve.last()
            && w <= w0
        {
            return Err(pt.value_error("rpm", "engine speeds must increase"));
        }
        torque_curve.push((w, t));
    }
    if torque_curve.len() < 2 {
        return Err(points.error(&points.path, "the torque curve needs at least 2 points"));
    }
    let rev_limiter = positive(
        engine,
        "revs limiter",
        engine.num_or("revs limiter", engine.num_or("revs maxi", 800.0)?)?,
    )?;
    let tickover = engine.num_or("tickover", 100.0)?;
    let revs_max = engine.num_or("revs maxi", 1000.0)?;
    if !(revs_max > tickover && revs_max.is_finite()) {
        return Err(engine.value_error(
            "revs maxi",
            format!("must be above the tickover ({tickover} rad/s), got {revs_max} rad/s"),
        ));
    }
    let engine_brake = engine.num_or("brake coefficient", DEFAULT_ENGINE_BRAKE)?;
    if !(engine_brake >= 0.0 && engine_brake.is_finite()) {
        return Err(engine.value_error(
            "brake coefficient",
            format!("must be non-negative, got {engine_brake}"),
        ));
    }
    let engine_inertia = positive(engine, "inertia", engine.num_or("inertia", 0.2)?)?;

    let gearbox = p.require_section("Gearbox")?;
    let shift_time = gearbox.num_or("shift time", 0.2)?;
    let mut gears = Vec::new();
    for i in 1..=10 {
        match gearbox.section(&format!("gears/{i}")) {
            Some(g) => gears.push(positive(g, "ratio", g.require_num("ratio")?)?),
            None => break,
        }
    }
    if gears.is_empty() {
        return Err(gearbox.error("Gearbox/gears", "no forward gears (sections 1, 2, ...)"));
    }
    let drive = match sec("Drivetrain").str("type").unwrap_or("RWD") {
        "RWD" => Drive::Rear,
        "FWD" => Drive::Front,
        "4WD" => Drive::All,
        other => {
            return Err(sec("Drivetrain").value_error(
                "type",
                format!("unknown drivetrain {other:?} (RWD, FWD or 4WD)"),
            ));
        }
    };
    let diff = |name: &str| sec(name).num_or("ratio", 1.0);
    let (final_drive, diff_section) = match drive {
        Drive::Rear => (diff("Rear Differential")?, "Rear Differential"),
        Drive::Front => (diff("Front Differential")?, "Front Differential"),
        Drive::All => (
            diff("Central Differential")? * diff("Rear Differential")?,
            "Central Differential",
        ),
    };

    let tyre = |name: &str, static_load: f64| -> Result<Tyre> {
        let w = sec(name);
        let camber = w.num_or("camber", 0.0)?;
        let rim = w.num_or("rim diameter", 0.33)?;
        let width = w.num_or("tire width", 0.145)?;
        let aspect = w.num_or("tire height-width ratio", 0.75)?;
        let brake = sec(&name.replace("Wheel", "Brake"));
        Ok(Tyre {
            radius: positive(w, "rim diameter", rim / 2.0 + width * aspect)?,
            mu: positive(w, "mu", w.num_or("mu", 1.0)?)? * camber_grip(camber),
            stiffness: positive(w, "stiffness", w.num_or("stiffness", 30.0)?)?,
            dynamic_friction: fraction(w, "dynamic friction", w.num_or("dynamic friction", 0.8)?)?,
            elasticity: w.num_or("elasticity factor", 0.7)?,
            operating_load: positive(
                w,
                "operating load",
                w.num_or("operating load", 1.2 * static_load)?,
            )?,
            // TORCS's simuv2 takes rolling resistance from the road's surface, not the tyre:
            // a car file without one rolls like the game's asphalt (0.001).
            rolling_resistance: w.num_or("rolling resistance", ASPHALT_ROLLING_RESISTANCE)?,
            inertia: w.num_or("inertia", 1.5)? + brake.num_or("inertia", 0.13)?,
            skid: SKID_FACTOR,
        })
    };
    let brake = |name: &str| -> Result<Brake> {
        let b = sec(name);
        Ok(Brake {
            disc_radius: positive(b, "disk diameter", b.num_or("disk diameter", 0.2)? / 2.0)?,
            piston_area: positive(b, "piston area", b.num_or("piston area", 0.002)?)?,
            pad_mu: positive(b, "mu", b.num_or("mu", DEFAULT_PAD_MU)?)?,
        })
    };
    // The suspension of the right-hand wheels (simuv2's `susp.cpp` and `wheel.cpp`): spring
    // rate K, bellcrank b, course c and the wheel's ride height x₀ under its static load.
    let ride = {
        /// One wheel's suspension, as [`Ride`] keeps it per axle.
        struct Wheel {
            height: f64,
            rate: f64,
            travel: f64,
            bellcrank: f64,
            damper: Damper,
            mass: f64,
        }
        let axle = |susp: &str, wheel: &str| -> Result<Wheel> {
            let (s, w) = (sec(susp), sec(wheel));
            let bellcrank = positive(s, "bellcrank", s.num_or("bellcrank", 1.0)?)?;
            let spring = positive(s, "spring", s.num_or("spring", 175_000.0)?)?;
            let course = positive(s, "suspension course", s.num_or("suspension course", 0.5)?)?;
            let height = positive(w, "ride height", w.num_or("ride height", 0.2)?)?;
            // simuv2's `SimSuspConfig`: the slow rates default to 0, the fast ones to the
            // slow, the thresholds to 0.5 m/s.
            let curve = |way: &str| -> Result<DamperCurve> {
                let slow_name = format!("slow {way}");
                let slow = non_negative(s, &slow_name, s.num_or(&slow_name, 0.0)?)?;
                let fast_name = format!("fast {way}");
                let fast = non_negative(s, &fast_name, s.num_or(&fast_name, slow)?)?;
                let threshold_name = format!("fast {way} threshold");
                let threshold = positive(s, &threshold_name, s.num_or(&threshold_name, 0.5)?)?;
                Ok(DamperCurve {
                    slow,
                    fast,
                    threshold,
                })
            };
            let damper = Damper {
                bump: curve("bump")?,
                rebound: curve("rebound")?,
            };
            Ok(Wheel {
                height,
                rate: spring * bellcrank * bellcrank,
                travel: course / bellcrank,
                bellcrank,
                damper,
                mass: positive(w, "mass", w.num_or("mass", 20.0)?)?,
            })
        };
        let f = axle("Front Right Suspension", "Front Right Wheel")?;
        let r = axle("Rear Right Suspension", "Rear Right Wheel")?;
        Ride {
            height: [f.height, r.height],
            load: static_wheel_load,
            rate: [f.rate, r.rate],
            travel: [f.travel, r.travel],
            bellcrank: [f.bellcrank, r.bellcrank],
            dampers: [f.damper, r.damper],
            wheel_mass: [f.mass, r.mass],
        }
    };
    // The axles as simuv2 loads their wheels in a corner (`axle.cpp`, `susp.cpp`, `car.cpp`):
    // the wheels' |y|, the roll centres (0.15 m by default), and each wheel's rate in roll,
    // K·b² of its spring plus 2·K_arb·b of the axle's anti-roll bar (0 by default).
    let axles = {
        let axle = |axle: &str, wheel: &str, susp: &str, arb: &str| -> Result<(f64, f64, f64)> {
            let (a, w, s) = (sec(axle), sec(wheel), sec(susp));
            let bellcrank = positive(s, "bellcrank", s.num_or("bellcrank", 1.0)?)?;
            let spring = s.num_or("spring", 175_000.0)?;
            let bar = sec(arb).num_or("spring", 0.0)?;
            let rate = spring * bellcrank * bellcrank + 2.0 * bar * bellcrank;
            if !(rate >= 0.0 && rate.is_finite()) {
                return Err(s.value_error("spring", format!("must be non-negative, got {spring}")));
            }
            Ok((
                w.num_or("ypos", 0.0)?.abs(),
                a.num_or("roll center height", 0.15)?,
                rate,
            ))
        };
        let f = axle(
            "Front Axle",
            "Front Right Wheel",
            "Front Right Suspension",
            "Front Anti-Roll Bar",
        )?;
        let r = axle(
            "Rear Axle",
            "Rear Right Wheel",
            "Rear Right Suspension",
            "Rear Anti-Roll Bar",
        )?;
        Axles {
            half_track: [f.0, r.0],
            roll_centre: [f.1, r.1],
            roll_rate: [f.2, r.2],
            pitch_height: cg_height + 0.5 * (ride.height[0] + ride.height[1]),
        }
    };
    // The rear differential (`differential.cpp`; defaults of TORCS 1.3's simuv2). A viscous
    // coupler or none on a driven axle is taken as a free differential.
    let differential = {
        let d = sec("Rear Differential");
        let kind = match d.str("type").unwrap_or("NONE") {
            "SPOOL" => DiffKind::Spool,
            "LIMITED SLIP" => DiffKind::LimitedSlip,
            _ => DiffKind::Free,
        };
        let lock_torque = positive(
            d,
            "locking input torque",
            d.num_or("locking input torque", 3000.0)?,
        )?;
        Differential {
            kind,
            slip_max: d.num_or("max slip bias", 0.03)?.max(0.0),
            lock_torque,
            lock_brake_torque: positive(
                d,
                "locking brake input torque",
                d.num_or("locking brake input torque", 0.33 * lock_torque)?,
            )?,
        }
    };
    let brakes = sec("Brake System");
    Ok(Car {
        name: p.root.name.clone(),
        mass,
        cg_height,
        front_weight,
        wheelbase,
        yaw_inertia_factor,
        cx,
        front_area,
        clift,
        wings,
        ride: Some(ride),
        axles,
        differential,
        torque_curve,
        rev_limiter,
        tickover,
        revs_max,
        engine_brake,
        engine_inertia,
        gears,
        final_drive: positive(sec(diff_section), "ratio", final_drive)?,
        shift_time,
        drive,
        front_tyre: tyre("Front Right Wheel", static_wheel_load[0])?,
        rear_tyre: tyre("Rear Right Wheel", static_wheel_load[1])?,
        brake_pressure: positive(
            brakes,
            "max pressure",
            brakes.num_or("max pressure", 1.0e7)?,
        )?,
        brake_front_share: fraction(
            brakes,
            "front-rear brake repartition",
            brakes.num_or("front-rear brake repartition", 0.5)?,
        )?,
        front_brake: brake("Front Right Brake")?,
        rear_brake: brake("Rear Right Brake")?,
        steer_lock: positive(
            sec("Steer"),
            "steer lock",
            sec("Steer").num_or("steer lock", 0.43)?,
        )?,
        width: positive(car, "overall width", car_width(car)?)?,
        length: body_length,
        torcs_robot: true,
        scales: super::Scales::ONE,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A category file (TORCS layout: `categories/CAT.xml`) with `category_extra` in its `Car`
    /// section, and a car `cars/NAME/NAME.xml` over it with `car_extra` in its own.
    fn car_over_category(tag: &str, category_extra: &str, car_extra: &str) -> (PathBuf, PathBuf) {
        let dir = crate::scratch::dir(&format!("car-category-{tag}"));
        std::fs::create_dir_all(dir.join("categories")).unwrap();
        std::fs::create_dir_all(dir.join("cars/test-car")).unwrap();
        let category = dir.join("categories/test-cat.xml");
        std::fs::write(
            &category,
            format!(
                r#"<?xml version="1.0"?>
<params name="test-cat">
  <section name="Car">
    <attnum name="mass" val="1000"/>
    {category_extra}
  </section>
  <section name="Engine">
    <section name="data points">
      <section name="1"><attnum name="rpm" val="0"/><attnum name="Tq" val="100"/></section>
      <section name="2"><attnum name="rpm" val="800"/><attnum name="Tq" val="200"/></section>
    </section>
  </section>
  <section name="Gearbox"><section name="gears"><section name="1">
    <attnum name="ratio" val="3"/>
  </section></section></section>
</params>
"#
            ),
        )
        .unwrap();
        let car = dir.join("cars/test-car/test-car.xml");
        std::fs::write(
            &car,
            format!(
                r#"<?xml version="1.0"?>
<params name="test-car">
  <section name="Car">
    <attstr name="category" val="test-cat"/>
    {car_extra}
  </section>
</params>
"#
            ),
        )
        .unwrap();
        (car, category)
    }

    /// A bad value names the file it is in, and its line there: the category file for a value
    /// the car inherits from it, the car file for one the car sets.
    #[test]
    fn a_bad_value_names_the_file_it_came_from() {
        // simuv2 moves the mass and the fuel, 80 (kg) when neither file names a fuel.
        let (car, _) = car_over_category("ok", "", "");
        assert_eq!(read(&car, None).unwrap().mass, 1080.0);

        let bad_number = r#"<attnum name="GC height" val="-0.3"/>"#;
        let (car, _) = car_over_category("cat", bad_number, "");
        let e = read(&car, None).unwrap_err().to_string();
        let at_line_5 = "/categories/test-cat.xml:5: Car/GC height: must be positive, got -0.3";
        assert!(e.ends_with(at_line_5) && !e.contains("test-car.xml"), "{e}");

        let a_string = r#"<attstr name="front-rear weight repartition" val="half"/>"#;
        let (car, _) = car_over_category("str", a_string, "");
        let e = read(&car, None).unwrap_err().to_string();
        let at_line_5 = "/categories/test-cat.xml:5: Car/front-rear weight repartition: expected a number (<attnum>), found the string \"half\"";
        assert!(e.ends_with(at_line_5) && !e.contains("test-car.xml"), "{e}");

        let (car, _) = car_over_category("car", "", r#"<attnum name="mass" val="0"/>"#);
        let e = read(&car, None).unwrap_err().to_string();
        let car_line_5 = format!("{}:5: Car/mass: must be positive, got 0", car.display());
        assert!(e.starts_with(&car_line_5), "{e}");

        // A value missing from both is reported at the car's own section.
        let (car, category) = car_over_category("gone", "", "");
        let text = std::fs::read_to_string(&category).unwrap();
        std::fs::write(
            &category,
            text.replace(r#"<attnum name="mass" val="1000"/>"#, ""),
        )
        .unwrap();
        let e = read(&car, None).unwrap_err().to_string();
        let car_line_3 = format!("{}:3: Car/mass: missing required attribute", car.display());
        assert!(e.starts_with(&car_line_3), "{e}");
    }
}
