//! Vehicle parameters, in SI units, as the simulator and the limit solver use them.
//!
//! Read from TORCS / Speed Dreams car files merged over their category ([`torcs`]); the
//! built-in default is the paper's car, the Speed Dreams Spirit 300 ([`Car::spirit_300`]).

pub mod calibration;
pub mod catalog;
pub mod torcs;

use serde::Serialize;

pub use calibration::Scales;

/// Which axle the engine drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Drive {
    /// Rear-wheel drive.
    Rear,
    /// Front-wheel drive.
    Front,
    /// Four-wheel drive, torque split evenly.
    All,
}

/// One axle's tyres (both wheels alike) in the TORCS tyre model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Tyre {
    /// Rolling radius (m): rim diameter / 2 + tyre width × aspect ratio.
    pub radius: f64,
    /// Peak friction coefficient μ, with the camber's grip where the car file gives a camber
    /// (simuv2's `wheel.cpp` multiplies the force by 1 + 0.05·sin(−18·camber), camber in rad).
    pub mu: f64,
    /// Magic-Formula stiffness (TORCS `stiffness`, = B·C).
    pub stiffness: f64,
    /// Dynamic friction ratio (TORCS `dynamic friction`, a fraction) sets the shape C.
    pub dynamic_friction: f64,
    /// Curvature factor E (TORCS `elasticity factor`).
    pub elasticity: f64,
    /// Load at which μ is nominal (N).
    pub operating_load: f64,
    /// Rolling-resistance coefficient.
    pub rolling_resistance: f64,
    /// Rotational inertia of one wheel with its brake disc (kg·m²).
    pub inertia: f64,
    /// The skid factor k: TORCS's simuv2 (`wheel.cpp`) multiplies the force by
    /// 1 + k·min(s, 1.5) for the slip's magnitude s, k from the driver's skill level
    /// (`categories.cpp`: 0.4, 0.35, 0.3, 0 for rookie, amateur, semi-pro, pro); 0 for a car
    /// that is not the game's.
    pub skid: f64,
}

/// The suspension as it sets the body's ride height, which TORCS's simuv2 (`aero.cpp`) makes
/// the body's downforce depend on: Fᵢ = Clᵢ·v²·h(Σ), h(Σ) = 2·exp(−3·(1.5·Σ)⁴), Σ the four
/// wheels' ride heights summed (car1-trb1 with its fuel: h = 1.45 at rest, 1.78 at 55 m/s as the
/// downforce compresses the springs, a body downforce 17 % and 44 % above 0.645·Cl·A·v²). A
/// wheel under load F_z rides at x₀ − (F_z − F₀)/k (`susp.cpp`),
/// within [0, its travel].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Ride {
    /// Ride height x₀ of a front and of a rear wheel under its static load F₀ (m).
    pub height: [f64; 2],
    /// F₀ of a front and of a rear wheel (N): simuv2's `weight0`, from the mass without fuel.
    pub load: [f64; 2],
    /// Wheel rate k of a front and of a rear wheel (N/m): the spring's rate times the
    /// bellcrank's ratio squared.
    pub rate: [f64; 2],
    /// Travel of a front and of a rear wheel (m): the suspension course over the bellcrank.
    pub travel: [f64; 2],
    /// The bellcrank's ratio b of a front and of a rear wheel: the spring and the damper
    /// move b metres a metre of the wheel's.
    pub bellcrank: [f64; 2],
    /// The damper of a front and of a rear wheel.
    pub dampers: [Damper; 2],
    /// The mass of a front and of a rear wheel (kg; simuv2's default 20).
    pub wheel_mass: [f64; 2],
}

/// A damper as simuv2's `susp.cpp` has it: at the damper's speed v (positive in bump,
/// compressing) its force is C₁·|v| below the threshold v₁ and C₂·|v| + (C₁ − C₂)·v₁ above
/// it, against the motion, each way with its own [`DamperCurve`]; |v| is capped at 10 m/s.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Damper {
    /// Compressing (`slow bump`, `fast bump`, `fast bump threshold`).
    pub bump: DamperCurve,
    /// Extending (`slow rebound`, `fast rebound`, `fast rebound threshold`).
    pub rebound: DamperCurve,
}

/// One way of a [`Damper`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DamperCurve {
    /// C₁ (N·s/m).
    pub slow: f64,
    /// C₂ (N·s/m).
    pub fast: f64,
    /// v₁ (m/s).
    pub threshold: f64,
}

impl DamperCurve {
    /// The force's size at the damper's speed |v| (N).
    #[inline]
    pub fn force(&self, speed: f64) -> f64 {
        let v = speed.abs().min(DAMPER_SPEED_CAP);
        if v < self.threshold {
            self.slow * v
        } else {
            self.fast * v + (self.slow - self.fast) * self.threshold
        }
    }
}

impl Damper {
    /// The damper's force at speed v (N, positive pushing the wheel out against a
    /// compression).
    #[inline]
    pub fn force(&self, v: f64) -> f64 {
        if v < 0.0 {
            -self.rebound.force(v)
        } else {
            self.bump.force(v)
        }
    }
}

/// The damper's speed simuv2 caps (m/s).
pub const DAMPER_SPEED_CAP: f64 = 10.0;

impl Ride {
    /// h(Σ) = 2·exp(−3·(1.5·Σ)⁴) of simuv2's `aero.cpp`, Σ the ride heights' sum (m).
    pub fn ground_effect(sum: f64) -> f64 {
        let x = 1.5 * sum;
        let x2 = x * x;
        2.0 * (-3.0 * x2 * x2).exp()
    }

    /// The sum of the four wheels' ride heights (m) when a front wheel carries `front` and a
    /// rear wheel `rear` (N).
    pub fn height_sum(&self, front: f64, rear: f64) -> f64 {
        [front, rear]
            .iter()
            .enumerate()
            .map(|(k, &fz)| {
                2.0 * (self.height[k] - (fz - self.load[k]) / self.rate[k])
                    .clamp(0.0, self.travel[k])
            })
            .sum()
    }
}

/// The axles as TORCS's simuv2 loads their wheels in a corner (`car.cpp`, `axle.cpp`,
/// `susp.cpp`): each wheel's lateral force Fᵧ pushes the body about its roll axis at the
/// axle's roll centre height, not at the centre of gravity (`car.cpp`: M_x = Σ F_z·y +
/// Σ Fᵧ·h_rc), and the springs and anti-roll bars take that moment up in proportion to their
/// roll rates. With the body rolled by φ a wheel at y carries κ·y·φ more (the left) or less,
/// κ = K·b² + 2·K_arb·b its rate in roll (spring K, bellcrank b, anti-roll bar K_arb), so in
/// the steady roll the axle a moves ΔF_a = M·κ_a·y_a / (2·Σ_b κ_b·y_b²) from its inner wheel
/// to its outer one, M = Σ_a Fᵧ,a·h_rc,a.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Axles {
    /// Half the track of the front and rear axles, |y| of their wheels (m).
    pub half_track: [f64; 2],
    /// Roll centre height of the front and rear axles (m), TORCS `roll center height`.
    pub roll_centre: [f64; 2],
    /// Rate in roll κ = K·b² + 2·K_arb·b of a front and of a rear wheel (N/m).
    pub roll_rate: [f64; 2],
    /// The height above the road at which the tyres' longitudinal forces pitch the body
    /// (m): simuv2 takes the centre of gravity's height plus the wheel's ride height
    /// (`car.cpp`: M_y = −Σ Fₓ·(h + x_ride)); the load moved from front to rear is
    /// ΣFₓ·(that height)/L.
    pub pitch_height: f64,
}

/// The kind of differential of the driven rear axle ([`Differential`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum DiffKind {
    /// Both wheels on one shaft.
    Spool,
    /// An open differential (simuv2's FREE).
    Free,
    /// simuv2's LIMITED SLIP.
    LimitedSlip,
}

/// The rear differential as TORCS's simuv2 drives the rear wheels through it
/// (`differential.cpp`; [`crate::vehicle`] has the formulas).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Differential {
    /// Its kind.
    pub kind: DiffKind,
    /// The wheels' largest speed ratio |ω₀ − ω₁|/(|ω₀| + |ω₁|) without drive torque (TORCS
    /// `max slip bias`, 0.03 by default).
    pub slip_max: f64,
    /// Drive torque at the differential (N·m) from which a limited slip locks (TORCS
    /// `locking input torque`, 3000 by default).
    pub lock_torque: f64,
    /// Braking (engine brake) torque from which it locks (N·m; TORCS `locking brake input
    /// torque`, a third of the locking input torque by default).
    pub lock_brake_torque: f64,
}

/// One axle's brakes (both wheels alike).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Brake {
    /// Disc radius (m).
    pub disc_radius: f64,
    /// Piston area (m²).
    pub piston_area: f64,
    /// Pad friction coefficient.
    pub pad_mu: f64,
}

/// A wing (TORCS `Front Wing` / `Rear Wing`): at speed v it pushes down with
/// F_z = 4·1.23·A·sin α·v² and drags with F_x = 1.23·A·sin α·v² (simuv2's `aero.cpp`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
pub struct Wing {
    /// Area A (m²); 0 for no wing.
    pub area: f64,
    /// Angle of attack α (rad).
    pub angle: f64,
    /// Share of its downforce on the front axle, by the lever rule: (x_wing − x_rear) / L.
    pub front_share: f64,
    /// Height z of the wing (m, TORCS `zpos`), the arm of its drag's pitching moment
    /// ([`Car::wing_pitch_per_v2`]).
    pub height: f64,
}

impl Wing {
    /// Drag per v² (kg/m): 1.23·A·sin α.
    pub fn drag_per_v2(&self) -> f64 {
        WING_AIR_DENSITY * self.area * self.angle.sin()
    }

    /// Downforce per v² (kg/m): 4·1.23·A·sin α.
    pub fn downforce_per_v2(&self) -> f64 {
        4.0 * self.drag_per_v2()
    }
}

/// The air density TORCS's wings use (kg/m³).
const WING_AIR_DENSITY: f64 = 1.23;

/// A car.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Car {
    /// Display name.
    pub name: String,
    /// Mass with driver and fuel (kg).
    pub mass: f64,
    /// Height of the centre of gravity (m).
    pub cg_height: f64,
    /// Fraction of the static weight on the front axle.
    pub front_weight: f64,
    /// Distance between the axles (m).
    pub wheelbase: f64,
    /// Yaw inertia factor k: I_z = k·m·a·b. For a TORCS car file, the factor that gives
    /// simuv2's I_z = m₀·(w² + c²·l²)/12 (m₀ the mass without fuel, w and l the body's width
    /// and length, c the `mass repartition coefficient`).
    pub yaw_inertia_factor: f64,
    /// Drag coefficient Cx.
    pub cx: f64,
    /// Frontal area (m²).
    pub front_area: f64,
    /// Lift coefficients of the front and rear axles (positive pushes down).
    pub clift: [f64; 2],
    /// Front and rear wings.
    pub wings: [Wing; 2],
    /// The suspension's ride height, for a body downforce that depends on it as in TORCS's
    /// simuv2 ([`Ride`]; a TORCS car file gives it); `None`: Fᵢ = 0.645·Clᵢ·A·v².
    pub ride: Option<Ride>,
    /// Engine torque curve: (engine speed rad/s, torque N·m), increasing speed.
    pub torque_curve: Vec<(f64, f64)>,
    /// Rev limiter (rad/s): no torque above it.
    pub rev_limiter: f64,
    /// Idle speed (rad/s): the clutch slips below it.
    pub tickover: f64,
    /// Highest engine speed (rad/s), TORCS `revs maxi`: where the engine brake is full.
    pub revs_max: f64,
    /// Engine brake coefficient c (TORCS `brake coefficient`): at throttle a and engine speed
    /// ω the engine gives T(ω)·(a·(1 + K) − K), K = c·(ω − ω_idle)/(ω_max − ω_idle)
    /// (simuv2's `engine.cpp`), so a closed throttle brakes harder the faster it turns.
    pub engine_brake: f64,
    /// Engine rotational inertia (kg·m²). TORCS's simuv2 does not load the wheels with it,
    /// and neither does [`crate::vehicle`].
    pub engine_inertia: f64,
    /// Forward gear ratios, first gear first.
    pub gears: Vec<f64>,
    /// Final drive (differential) ratio.
    pub final_drive: f64,
    /// Time without drive during a gear change (s).
    pub shift_time: f64,
    /// Driven axle(s).
    pub drive: Drive,
    /// Front tyres.
    pub front_tyre: Tyre,
    /// Rear tyres.
    pub rear_tyre: Tyre,
    /// Maximum brake line pressure (Pa).
    pub brake_pressure: f64,
    /// Fraction of the pressure sent to the front brakes.
    pub brake_front_share: f64,
    /// Front brakes.
    pub front_brake: Brake,
    /// Rear brakes.
    pub rear_brake: Brake,
    /// Largest road-wheel steering angle (rad).
    pub steer_lock: f64,
    /// Overall width of the body (m), TORCS `Car/overall width` (else `body width`): how
    /// much of the road a racing line leaves between the car's centre and the edge.
    pub width: f64,
    /// Length of the body (m), TORCS `Car/body length`: with [`Car::width`] it places the
    /// body's corners at (±length/2, ±width/2) from the centre of gravity, the four points
    /// simuv2 collides with the barriers (`collide.cpp`, `SimCarCollideXYScene`).
    pub length: f64,
    /// The axles' track, roll centres and roll rates: how the wheels share the load in a
    /// corner and under acceleration ([`Axles`]).
    pub axles: Axles,
    /// The rear axle's differential ([`Differential`]); a rear axle without drive has its
    /// wheels roll free.
    pub differential: Differential,
    /// Whether cdbo's simulator drives the car as cdbo's TORCS robot drives the game's car (a
    /// car read from TORCS files): pulling away on simuv2's slipping clutch, closed by the
    /// robot's launch clutch ([`crate::vehicle::aids::launch`]), and with the robot's traction control
    /// on the driven wheels' slip speed ([`crate::vehicle::aids::traction`]). Else (the built-in car)
    /// the clutch slips only below idle and traction control acts on the relative slip.
    pub torcs_robot: bool,
    /// Calibration scales over the car file's values ([`calibration`]): 1 for a stock car.
    /// Grip and peak slip are already in the tyres; drag, downforce, rolling resistance and
    /// the launch are applied where those forces are computed.
    pub scales: Scales,
}

impl Car {
    /// The Speed Dreams Spirit 300 (`sc-spirit-300.xml` over `Supercars.xml`), the paper's car.
    pub fn spirit_300() -> Car {
        let rpm = std::f64::consts::PI / 30.0;
        let curve_rpm_nm = [
            (0.0, 2000.0),
            (500.0, 180.0),
            (1000.0, 262.0),
            (1500.0, 282.0),
            (2000.0, 295.0),
            (2500.0, 305.0),
            (3000.0, 310.0),
            (3500.0, 314.0),
            (4000.0, 320.0),
            (4500.0, 330.0),
            (5000.0, 340.0),
            (5500.0, 350.0),
            (6000.0, 360.0),
            (6500.0, 368.0),
            (7000.0, 370.0),
            (7500.0, 372.0),
            (8000.0, 350.0),
            (8500.0, 310.0),
            (9000.0, 241.0),
        ];
        let tyre = |width: f64, aspect: f64, load: f64, inertia: f64| Tyre {
            radius: 17.0 * 0.0254 / 2.0 + width * aspect,
            mu: 1.3,
            stiffness: 16.0,
            dynamic_friction: 0.6,
            elasticity: 0.86,
            operating_load: load,
            rolling_resistance: 0.01,
            inertia,
            skid: 0.0,
        };
        Car {
            name: "Spirit 300".into(),
            mass: 1440.0,
            cg_height: 0.285,
            front_weight: 0.44,
            wheelbase: 1.235 + 1.5,
            yaw_inertia_factor: 0.62,
            cx: 0.32,
            front_area: 1.85,
            clift: [0.65, 0.61],
            wings: [Wing::default(); 2],
            ride: None,
            torque_curve: curve_rpm_nm.iter().map(|&(r, t)| (r * rpm, t)).collect(),
            rev_limiter: 8500.0 * rpm,
            tickover: 2000.0 * rpm,
            revs_max: 10000.0 * rpm,
            engine_brake: DEFAULT_ENGINE_BRAKE,
            engine_inertia: 0.15,
            gears: vec![3.66, 2.18, 1.4, 1.02, 0.85, 0.76],
            final_drive: 4.5,
            shift_time: 0.4,
            drive: Drive::Rear,
            front_tyre: tyre(0.255, 0.40, 3200.0, 1.283 + 0.1241),
            rear_tyre: tyre(0.300, 0.37, 3800.0, 1.600 + 0.0714),
            brake_pressure: 13_000.0e3,
            brake_front_share: 0.52,
            front_brake: Brake {
                disc_radius: 0.190,
                piston_area: 50.0e-4,
                pad_mu: 0.45,
            },
            rear_brake: Brake {
                disc_radius: 0.165,
                piston_area: 30.0e-4,
                pad_mu: 0.25,
            },
            steer_lock: 45f64.to_radians(),
            width: 1.90,
            length: 4.2,
            // sc-spirit-300.xml: wheels at y = ±0.78 / ±0.80 m, roll centres 0.39 m, springs
            // 37 / 57 kN/m (bellcrank 1, no anti-roll bars), ride height 0.11 m; a limited-slip
            // differential with max slip bias 0.4 and simuv2's default locking torques.
            axles: Axles {
                half_track: [0.78, 0.80],
                roll_centre: [0.39, 0.39],
                roll_rate: [37.0e3, 57.0e3],
                pitch_height: 0.285 + 0.11,
            },
            differential: Differential {
                kind: DiffKind::LimitedSlip,
                slip_max: 0.4,
                lock_torque: 3000.0,
                lock_brake_torque: 990.0,
            },
            torcs_robot: false,
            scales: Scales::ONE,
        }
    }

    /// Distance from the centre of gravity to the front axle, a = (1 − front_weight)·L (m).
    pub fn cg_to_front(&self) -> f64 {
        (1.0 - self.front_weight) * self.wheelbase
    }

    /// Distance from the centre of gravity to the rear axle, b = front_weight·L (m).
    pub fn cg_to_rear(&self) -> f64 {
        self.front_weight * self.wheelbase
    }

    /// The axles' static loads [m·g·b/L, m·g·a/L] (N): the car's weight shared between the
    /// axles as its centre of gravity sits between them.
    pub fn static_axle_loads(&self) -> [f64; 2] {
        [
            self.mass * G * self.cg_to_rear() / self.wheelbase,
            self.mass * G * self.cg_to_front() / self.wheelbase,
        ]
    }

    /// Yaw inertia I_z = k·m·a·b (kg·m²).
    pub fn yaw_inertia(&self) -> f64 {
        self.yaw_inertia_factor * self.mass * self.cg_to_front() * self.cg_to_rear()
    }

    /// Engine torque at full throttle (N·m), linear between the curve's points, 0 past the
    /// rev limiter.
    pub fn engine_torque(&self, omega: f64) -> f64 {
        if omega >= self.rev_limiter {
            return 0.0;
        }
        crate::interp::linear(&self.torque_curve, omega)
    }

    /// Engine torque at throttle a ∈ [0, 1] and engine speed ω (N·m), the engine brake
    /// included: T(ω)·(a·(1 + K) − K), K = c·(ω − ω_idle)/(ω_max − ω_idle); `full` is T(ω).
    #[inline]
    pub fn part_throttle_torque(&self, full: f64, throttle: f64, omega: f64) -> f64 {
        let k = self.engine_brake * (omega - self.tickover) / (self.revs_max - self.tickover);
        full * (throttle * (1.0 + k) - k)
    }

    /// Largest full-throttle torque between idle and the rev limiter (N·m).
    pub fn peak_torque(&self) -> f64 {
        self.torque_curve
            .iter()
            .filter(|(w, _)| (self.tickover..=self.rev_limiter).contains(w))
            .map(|p| p.1)
            .fold(0.0, f64::max)
    }

    /// Brake torque of one wheel at full pedal (N·m): p·share·A_piston·μ_pad·r_disc.
    pub fn brake_torque(&self, front: bool) -> f64 {
        let (b, share) = if front {
            (&self.front_brake, self.brake_front_share)
        } else {
            (&self.rear_brake, 1.0 - self.brake_front_share)
        };
        self.brake_pressure * share * b.piston_area * b.pad_mu * b.disc_radius
    }

    /// Aerodynamic drag force at speed v: F = (0.645·Cx·A·v² plus the wings')·s_drag (N),
    /// 0.645 = ρ/2 with ρ = 1.29, s_drag the calibration's scale (1 for a stock car).
    pub fn drag(&self, v: f64) -> f64 {
        let wings: f64 = self.wings.iter().map(Wing::drag_per_v2).sum();
        (AIR_HALF_RHO * self.cx * self.front_area + wings) * v * v * self.scales.drag
    }

    /// The load the wings' drag moves from the rear axle onto the front per v² (kg/m):
    /// Σ 1.23·A·sin α·z / L over the wings, times the calibration's drag scale. simuv2's
    /// `car.cpp` pitches the body by M_y −= Fₓ·z for each wing's drag Fₓ < 0 at its height z,
    /// where a force's moment about the centre of gravity is z·Fₓ: in the game a wing's drag
    /// loads the front. At 50 m/s car1-trb1's wings put 196 N on the front axle and take as
    /// much from the rear, 195 N of it the rear wing's (0.7 m² at 14°, z = 0.99 m).
    pub fn wing_pitch_per_v2(&self) -> f64 {
        let moment: f64 = self.wings.iter().map(|w| w.drag_per_v2() * w.height).sum();
        moment / self.wheelbase * self.scales.drag
    }

    /// Downforce on the front and rear axles at speed v, level road and no acceleration: the
    /// body's Fᵢ = 0.645·Clᵢ·A·v², or with a [`Ride`] simuv2's Clᵢ·v²·h(Σ) at the ride heights
    /// the car settles at under its weight and this downforce; plus the wings', each shared
    /// between the axles by its position; times the calibration's scale (N).
    pub fn downforce(&self, v: f64) -> [f64; 2] {
        let v2 = v * v;
        let mut wings = [0.0; 2];
        for w in &self.wings {
            let d = w.downforce_per_v2() * v2;
            wings[0] += d * w.front_share;
            wings[1] += d * (1.0 - w.front_share);
        }
        let s = self.scales.downforce;
        let Some(ride) = &self.ride else {
            let q = AIR_HALF_RHO * self.front_area * v2;
            return [0, 1].map(|k| (q * self.clift[k] + wings[k]) * s);
        };
        let weight = self.static_axle_loads();
        let total = |sum: f64| {
            let h = Ride::ground_effect(sum);
            [0, 1].map(|k| (self.clift[k] * v2 * h + wings[k]) * s)
        };
        // The ride heights' sum Σ solves Σ = Σ_ride(loads(Σ)): the right side grows with Σ
        // (less ground effect, less load, less compression) more slowly than Σ, so bisect.
        let (mut lo, mut hi) = (0.0, 2.0 * (ride.travel[0] + ride.travel[1]));
        for _ in 0..50 {
            let mid = 0.5 * (lo + hi);
            let d = total(mid);
            let sum = ride.height_sum(0.5 * (weight[0] + d[0]), 0.5 * (weight[1] + d[1]));
            if sum > mid { lo = mid } else { hi = mid }
        }
        total(0.5 * (lo + hi))
    }
}

/// Gravity g (m/s²).
pub const G: f64 = 9.81;

/// Half the air density, ρ/2 (kg/m³), the 0.645 of TORCS's aerodynamics.
pub const AIR_HALF_RHO: f64 = 0.645;

/// Engine brake coefficient when a car file does not give one (simuv2's default).
pub const DEFAULT_ENGINE_BRAKE: f64 = 0.33;

/// Pad friction when a brake does not give one (TORCS's default).
pub const DEFAULT_PAD_MU: f64 = 0.30;

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A car with simuv2's ride height: car1-trb1's figures (its file is not in the repository).
    /// TORCS's `lbs/in` (and `lbs/in/s`) in SI: lbs is a mass to `GfParmGetNum`.
    const LBS_PER_IN: f64 = 0.453_592_37 / 0.0254;

    pub(crate) fn on_springs() -> Car {
        let rate = 5500.0 * LBS_PER_IN * 1.1 * 1.1;
        Car {
            mass: 1244.0,
            clift: [0.69, 0.7],
            ride: Some(Ride {
                height: [0.09, 0.105],
                load: [2932.0, 2706.0],
                rate: [rate, rate],
                travel: [0.2 / 1.1, 0.2 / 1.1],
                bellcrank: [1.1, 1.1],
                dampers: [Damper {
                    bump: DamperCurve {
                        slow: 400.0 * LBS_PER_IN,
                        fast: 60.0 * LBS_PER_IN,
                        threshold: 0.5,
                    },
                    rebound: DamperCurve {
                        slow: 300.0 * LBS_PER_IN,
                        fast: 60.0 * LBS_PER_IN,
                        threshold: 0.5,
                    },
                }; 2],
                wheel_mass: [20.0, 20.0],
            }),
            ..Car::spirit_300()
        }
    }

    /// h(Σ) = 2·exp(−3·(1.5·Σ)⁴): 2 on the ground, e^(−3) ·2 at 1.5·Σ = 1.
    #[test]
    fn the_ground_effect_is_simuv2s() {
        assert_eq!(Ride::ground_effect(0.0), 2.0);
        assert!((Ride::ground_effect(1.0 / 1.5) - 2.0 * (-3f64).exp()).abs() < 1e-12);
        assert!(Ride::ground_effect(0.3) > Ride::ground_effect(0.4));
    }

    /// The downforce solves its own ride height: the loads it and the weight put on the wheels
    /// compress the springs to the Σ at which the body's lift is Cl·v²·h(Σ); and it grows
    /// faster than v² as the car sinks.
    #[test]
    fn the_downforce_settles_the_ride_height_it_depends_on() {
        let car = on_springs();
        let ride = car.ride.unwrap();
        let wings = |v: f64| {
            let mut w = [0.0; 2];
            for wing in &car.wings {
                w[0] += wing.downforce_per_v2() * v * v * wing.front_share;
                w[1] += wing.downforce_per_v2() * v * v * (1.0 - wing.front_share);
            }
            w
        };
        let mut last = 0.0;
        for v in [1.0, 20.0, 40.0, 60.0, 80.0] {
            let d = car.downforce(v);
            let w = wings(v);
            let (a, b, l) = (car.cg_to_front(), car.cg_to_rear(), car.wheelbase);
            let sum = ride.height_sum(
                0.5 * (car.mass * G * b / l + d[0]),
                0.5 * (car.mass * G * a / l + d[1]),
            );
            let h = Ride::ground_effect(sum);
            for k in 0..2 {
                let body = car.clift[k] * v * v * h;
                assert!(
                    (d[k] - w[k] - body).abs() < 1e-6 * d[k].max(1.0),
                    "{v}: {d:?}"
                );
            }
            let per_v2 = (d[0] + d[1]) / (v * v);
            assert!(per_v2 > last, "{v}: {per_v2} after {last}");
            last = per_v2;
        }
        // At 60 m/s the springs give 25 mm a wheel and the ground effect 1.7.
        let d = car.downforce(60.0);
        let h = (d[0] + d[1] - wings(60.0)[0] - wings(60.0)[1]) / (1.39 * 3600.0);
        assert!((1.6..1.9).contains(&h), "{h}");
    }

    #[test]
    fn spirit_300_has_the_papers_figures() {
        let c = Car::spirit_300();
        assert_eq!(c.mass, 1440.0);
        assert!((c.peak_torque() - 372.0).abs() < 1e-9);
        assert_eq!(c.gears.len(), 6);
        assert!((c.front_tyre.radius - 0.3179).abs() < 1e-3);
        // a + b = L, and the static front load fraction is b / L.
        assert!((c.cg_to_front() + c.cg_to_rear() - c.wheelbase).abs() < 1e-12);
        assert!((c.cg_to_rear() / c.wheelbase - 0.44).abs() < 1e-12);
    }

    #[test]
    fn torque_curve_interpolates_and_cuts_at_the_limiter() {
        let c = Car::spirit_300();
        let rpm = std::f64::consts::PI / 30.0;
        assert!((c.engine_torque(7250.0 * rpm) - 371.0).abs() < 1e-9);
        assert_eq!(c.engine_torque(8600.0 * rpm), 0.0);
    }
}
