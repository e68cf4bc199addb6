//! A two-track model with load transfer, wheel spin dynamics and the TORCS tyre, integrated
//! at a fixed step: the front wheels share one spin, the rear wheels turn each on its own
//! through the car's differential, as TORCS's simuv2 drives them.
//!
//! State: position (X, Y), yaw ψ, body velocities (vₓ, v_y), yaw rate r, the spin ω of the
//! front wheels and of each rear wheel. With a = CG→front axle, b = CG→rear axle, L = a + b:
//!
//! - Axle loads: F_zf = m·n·b/L − m·Āₓ·h_p/L + D_f + W·v², F_zr = m·n·a/L + m·Āₓ·h_p/L + D_r
//!   − W·v², with m·Āₓ the tyres' longitudinal force (lagged 50 ms), h_p the pitch height
//!   ([`crate::car::Axles::pitch_height`]: simuv2's `car.cpp` pitches the body by Fₓ·(h +
//!   ride height)), W·v² what the wings' drag moves onto the front axle as the game's body
//!   pitches ([`Car::wing_pitch_per_v2`]), D the downforce and n = g·cos φ·cos β + vₓ²·κ_v
//!   the road's push per unit mass: gravity on the grade φ and the banking β, and the road's
//!   vertical curvature κ_v = dφ/ds (negative over a crest, which unloads the car: at 31 m/s
//!   over Ruudskogen's crest at 320 m, κ_v ≈ −0.004 /m takes 40 % of the weight off, and the
//!   game's car1-trb1 slides out of the corner there as cdbo's now does). The banking's share
//!   of the cornering acceleration (vₓ·r·sin β) is left out: measured against the game, adding
//!   it places fewer of the game's failures (4 of 21 road tracks against 8).
//! - Wheel loads: each axle's inner wheel gives ΔF_a = M·κ_a·y_a/(2·Σ_b κ_b·y_b²) to its outer
//!   one, M = Σ_a Fᵧ,a·h_rc,a the tyres' lateral forces at the roll centres (simuv2's
//!   `car.cpp`; [`crate::car::Axles`]), lagged 70 ms.
//! - Tyres: each wheel's budget F_z·μ·μ_r·λ(F_z) ([`super::tyre`]) under its own load, μ_r
//!   the friction of the surface under the wheel's centre: the road's, or past the road's
//!   edge its border's or side's ([`crate::track::Verge`], `Vehicle::wheel_ground`), as
//!   simuv2's `wheel.cpp` takes each wheel's segment's surface. The
//!   front wheels share one spin; the inner one is steered by δ, the outer one by simuv2's
//!   Ackermann angle (`steer.cpp`), tan δ_o = L·tan|δ|/(L + T·tan|δ|), T = y_f + y_r (at
//!   δ = 0.15 rad, 0.013 rad less). The rear wheels' slips take each wheel's own velocity,
//!   vₓ ∓ r·y_r. The wheels' longitudinal forces at ±y add a yaw moment
//!   Σ y·(Fₓ,right − Fₓ,left) (simuv2's `car.cpp`: M_z = Σ −Fₓ·y + Fᵧ·x).
//! - Rear wheels: driven through a spool, a free or a limited-slip differential as simuv2's
//!   `differential.cpp` (`Vehicle::rear_wheels`).
//! - Wheel slip: for the wheel-frame velocity (v_t, v_l), sₓ = (ωR − v_t)/max(|v_t|, v₀) and
//!   s_y = −v_l/max(|v|, v₀), |v| = √(v_t² + v_l²), the sine of the slip angle as simuv2's
//!   `wheel.cpp` has it, with v₀ = [`SLIP_SPEED_FLOOR`]; the tyre ([`super::tyre`]) gives
//!   (Fₓ, F_y).
//! - Wheels: I·dω/dt = T_drive − T_brake·sgn ω − R·Fₓ(ω), integrated implicitly in ω (Fₓ
//!   linearised), so that the stiff slip dynamics stay stable at the 4 ms step. As in TORCS's
//!   simuv2 (whose differential takes its output inertia from the gear alone at each shift),
//!   the engine's inertia does not load the wheels: the engine speed follows them.
//! - Body: m(v̇ₓ − v_y r) = F_xf cos δ − F_yf sin δ + F_xr − F_drag − F_roll − m g sin φ,
//!   m(v̇_y + vₓ r) = F_xf sin δ + F_yf cos δ + F_yr − m g sin β,
//!   I_z ṙ = a(F_xf sin δ + F_yf cos δ) − b F_yr + y_r(F_x,rr − F_x,rl) − M_R, with β the
//!   banking, F_xr, F_yr the rear wheels' sums and M_R the rolling resistance's moment against
//!   the yaw, simuv2's R·L/2 (`car.cpp`; `Vehicle::rolling_yaw_moment`).
//! - Drag F = 0.645·Cx·A·v², downforce Dᵢ = 0.645·Clᵢ·A·v², rolling resistance
//!   F = Σᵢ c_rr,i·F_z,i·sgn vₓ, c_rr,i the surface's under wheel i where the track gives one
//!   (as TORCS's simuv2 does, `wheel.cpp`: F_z·`kRollRes` of the wheel's segment), else the
//!   tyres'; a calibrated car ([`crate::car::calibration`])
//!   scales drag, downforce and c_rr, and the drive torque in first gear (its launch).
//! - Brakes: T = p·share·A_piston·μ_pad·r_disc per wheel, with ABS easing the pressure while an
//!   axle's slip exceeds half the tyre's peak slip; traction control eases the throttle
//!   likewise (the Spirit 300 has both; TORCS robots implement them in the driver). A car the
//!   TORCS robot drives gets the robot's aids: traction control on the driven wheels' slip
//!   speed in every gear, and ABS once a driver step on the one brake command the four wheels
//!   share ([`Vehicle::driver_brake`]).
//! - Launch of a car the TORCS robot drives ([`Car::torcs_robot`]): as simuv2 does, a
//!   slipping clutch (transfer τ = 1 − c, c the robot's launch clutch, [`Vehicle::clutch`])
//!   leaves the engine unloaded, ω̇_e = T_e(ω_e)/I_e, blended with the wheels' speed by τ⁴,
//!   and gives the wheels its full torque T_e(ω_e)·g·min(3τ, 1): the engine revs towards its
//!   peak while the car pulls away (car1-trb1: 7500 rpm at 0.5 m, where a closed clutch turns
//!   it at idle, 900 rpm, and gives 100 of its 483 N·m). With the tyre's skid factor and the
//!   robot's traction control in first gear, cdbo's car1-trb1 reaches 100 m of full throttle
//!   within 0.02 s and 0.1 m/s of the game's on E-Track 2 and Ruudskogen (0.4 s behind before).

use super::bounce::{self, Bounce, Corner};
use super::powertrain::{EngineMap, Gearbox, ShiftMap};
use super::tyre::TyreModel;
use crate::car::{Car, DiffKind, Drive, G};
use crate::track::{Bumps, Frame};

/// Floor of the speed that normalises slip (m/s): keeps slip finite when standing.
pub const SLIP_SPEED_FLOOR: f64 = 2.0;
/// ABS and traction control start easing at this fraction of the tyre's peak slip as the car
/// file gives it (the driver's setting: a calibrated car's fitted tyre leaves it), and release
/// fully at twice it.
const AID_SLIP_RATIO: f64 = 0.5;

/// The driver's commands, held between driver updates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controls {
    steer: f64,
    throttle: f64,
    brake: f64,
    /// (sin, cos) of the steering angle, computed once per driver step.
    steer_sin_cos: (f64, f64),
}

impl Controls {
    /// Commands for a road-wheel steering angle (rad, positive left), a throttle and a brake
    /// pedal in [0, 1].
    pub fn new(steer: f64, throttle: f64, brake: f64) -> Controls {
        Controls {
            steer,
            throttle,
            brake,
            steer_sin_cos: steer.sin_cos(),
        }
    }

    /// Steering angle (rad).
    pub fn steer(&self) -> f64 {
        self.steer
    }

    /// Throttle in [0, 1].
    pub fn throttle(&self) -> f64 {
        self.throttle
    }

    /// Brake pedal in [0, 1].
    pub fn brake(&self) -> f64 {
        self.brake
    }
}

impl Default for Controls {
    fn default() -> Self {
        Controls::new(0.0, 0.0, 0.0)
    }
}

/// The state of the car.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct State {
    /// Position (m).
    pub x: f64,
    /// Position (m).
    pub y: f64,
    /// Yaw (rad).
    pub yaw: f64,
    /// Longitudinal velocity in the body frame (m/s).
    pub vx: f64,
    /// Lateral velocity in the body frame (m/s), positive left.
    pub vy: f64,
    /// Yaw rate (rad/s).
    pub yaw_rate: f64,
    /// Spin of the front wheels (one for both) and of the rear left and rear right wheels
    /// (rad/s).
    pub omega: [f64; 3],
    /// The tyres' longitudinal force in the body frame per unit mass (m/s²), lagged, for the
    /// longitudinal load transfer.
    pub ax: f64,
    /// The tyres' roll moment Σ Fᵧ·h_rc (N·m), lagged, for the lateral load transfer.
    pub roll: f64,
    /// Gearbox.
    pub gearbox: Gearbox,
    /// Engine speed (rad/s).
    pub engine_speed: f64,
    /// (sin, cos) of the yaw.
    pub yaw_sin_cos: (f64, f64),
    /// The clutch command c ∈ [0, 1] (1 = open), set at the driver's steps by
    /// [`Vehicle::clutch`]; 0 (closed) unless a lap's driver pulls away with it.
    pub clutch: f64,
    /// Time with the throttle open in first gear so far (s), the launch clutch's clock.
    pub launch_time: f64,
    /// Each wheel's bounce over rough ground and kinks ([`super::bounce`]), front left, front right,
    /// rear left, rear right.
    pub bounce: [Bounce; 4],
}

impl State {
    /// Speed over ground (m/s).
    pub fn speed(&self) -> f64 {
        (self.vx * self.vx + self.vy * self.vy).sqrt()
    }
}

/// A car ready to be simulated: its parameters and the derived constants.
#[derive(Debug, Clone)]
pub struct Vehicle {
    /// The car.
    pub car: Car,
    tyres: [TyreModel; 2],
    radius: [f64; 2],
    wheel_inertia: [f64; 2],
    max_brake: [f64; 2],
    driven: [f64; 2],
    shift_map: ShiftMap,
    engine_map: EngineMap,
    a: f64,
    b: f64,
    inv_yaw_inertia: f64,
    inv_mass: f64,
    rolling: f64,
    /// The calibration's scale of the rolling resistance (1 for a stock car).
    rolling_scale: f64,
    /// The calibration's scale of the drive torque in first gear (1 for a stock car).
    launch_scale: f64,
    /// m·g·b/L and m·g·a/L: the axles' static loads on level ground (N).
    static_load: [f64; 2],
    /// m·h_p/L: load moved from front to rear per m/s² of the tyres' longitudinal force per
    /// unit mass, h_p the pitch height ([`crate::car::Axles::pitch_height`]) (kg).
    transfer_per_accel: f64,
    /// Load moved from each axle's inner wheel to its outer one per N·m of roll moment,
    /// κ_a·y_a/(2·Σ_b κ_b·y_b²) (1/m) ([`crate::car::Axles`]).
    roll_share: [f64; 2],
    /// The farthest a wheel's centre is from the CG, √(max(a, b)² + max(y_f, y_r)²) (m).
    reach: f64,
    /// Slip at which ABS and traction control start easing, per axle.
    aid_threshold: [f64; 2],
    /// 0.645·Cx·A (kg/m).
    drag_per_v2: f64,
    /// The load the wings' drag moves onto the front axle per v² (kg/m,
    /// [`Car::wing_pitch_per_v2`]).
    wing_pitch_per_v2: f64,
    /// Downforce per v² per axle (kg/m) at speeds 0, [`DOWNFORCE_SPEED_STEP`], 2·… m/s
    /// ([`Car::downforce`]: constant, 0.645·Clᵢ·A plus the wings', without a ride height; a
    /// function of the speed with one), linear in between, the last held beyond.
    downforce_per_v2: Vec<[f64; 2]>,
    /// What moves a front and a rear wheel over rough ground ([`super::bounce`]); `None` for a
    /// car without a suspension ([`Car::ride`]), which rides rough ground as smooth.
    corners: Option<[Corner; 2]>,
}

/// What a wheel stands on: its surface's friction and rolling resistance coefficient, and the
/// bumps it meets.
#[derive(Debug, Clone, Copy)]
struct Ground {
    friction: f64,
    rolling: f64,
    bumps: Bumps,
}

impl Vehicle {
    /// Prepares a car for simulation.
    pub fn new(car: &Car) -> Vehicle {
        let driven = match car.drive {
            Drive::Rear => [0.0, 1.0],
            Drive::Front => [1.0, 0.0],
            Drive::All => [0.5, 0.5],
        };
        let l = car.wheelbase;
        let tyres = [
            TyreModel::new(&car.front_tyre),
            TyreModel::new(&car.rear_tyre),
        ];
        Vehicle {
            aid_threshold: [
                tyres[0].peak_slip / car.scales.peak_slip * AID_SLIP_RATIO,
                tyres[1].peak_slip / car.scales.peak_slip * AID_SLIP_RATIO,
            ],
            static_load: car.static_axle_loads(),
            transfer_per_accel: car.mass * car.axles.pitch_height / l,
            roll_share: {
                let (y, k) = (car.axles.half_track, car.axles.roll_rate);
                let sum = 2.0 * (k[0] * y[0] * y[0] + k[1] * y[1] * y[1]);
                if sum > 0.0 {
                    [k[0] * y[0] / sum, k[1] * y[1] / sum]
                } else {
                    [0.0; 2]
                }
            },
            reach: car
                .cg_to_front()
                .max(car.cg_to_rear())
                .hypot(car.axles.half_track[0].max(car.axles.half_track[1])),
            drag_per_v2: car.drag(1.0),
            wing_pitch_per_v2: car.wing_pitch_per_v2(),
            downforce_per_v2: match car.ride {
                None => vec![car.downforce(1.0)],
                Some(_) => (0..=DOWNFORCE_SPEEDS)
                    .map(|i| {
                        // At v → 0 the coefficient tends to its value at rest: take it at 1 mm/s.
                        let v = (i as f64 * DOWNFORCE_SPEED_STEP).max(1e-3);
                        car.downforce(v).map(|f| f / (v * v))
                    })
                    .collect(),
            },
            corners: car.ride.map(|ride| [0, 1].map(|k| Corner::of(&ride, k))),
            tyres,
            radius: [car.front_tyre.radius, car.rear_tyre.radius],
            wheel_inertia: [2.0 * car.front_tyre.inertia, car.rear_tyre.inertia],
            max_brake: [2.0 * car.brake_torque(true), car.brake_torque(false)],
            driven,
            shift_map: ShiftMap::new(car),
            engine_map: EngineMap::new(car),
            a: car.cg_to_front(),
            b: car.cg_to_rear(),
            inv_yaw_inertia: 1.0 / car.yaw_inertia(),
            inv_mass: 1.0 / car.mass,
            rolling: 0.5 * (car.front_tyre.rolling_resistance + car.rear_tyre.rolling_resistance),
            rolling_scale: car.scales.rolling,
            launch_scale: car.scales.launch,
            car: car.clone(),
        }
    }

    /// Downforce per v² (kg/m) of the front and rear axles at speed v (m/s).
    #[inline]
    pub fn downforce_per_v2(&self, v: f64) -> [f64; 2] {
        let table = &self.downforce_per_v2;
        if table.len() == 1 {
            return table[0];
        }
        let x = v / DOWNFORCE_SPEED_STEP;
        let i = x as usize;
        if i + 1 >= table.len() {
            return table[table.len() - 1];
        }
        let w = x - i as f64;
        let (a, b) = (table[i], table[i + 1]);
        [a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1])]
    }

    /// The tyre models of the front and rear axles.
    pub fn tyres(&self) -> &[TyreModel; 2] {
        &self.tyres
    }

    /// The rolling resistance's moment against the yaw (N·m), as simuv2's `car.cpp` turns the
    /// body: M = R·L/2 against the yaw rate r, R the rolling resistance Σᵢ c_rr,i·F_z,i, or
    /// r·I_z where R·L/(2·I_z) > |r| (the yaw then dies away over a second instead of turning
    /// back). On a road of c_rr = 0.02 (E-Track 2 and 3, G-Track 1) car1-trb1 meets some
    /// 420 N·m at 50 m/s; on Forza's 0.001, 20 N·m.
    fn rolling_yaw_moment(&self, rolling: f64, yaw_rate: f64) -> f64 {
        let half = 0.5 * rolling * self.car.wheelbase;
        if half * self.inv_yaw_inertia > yaw_rate.abs() {
            yaw_rate / self.inv_yaw_inertia
        } else {
            half.copysign(yaw_rate)
        }
    }

    /// The cornering stiffness C_α (N/rad) of the front and rear axles at speed v on level road
    /// of friction μ_r: the slope of the lateral force at zero slip, F_max·B·C, with the
    /// axle's budget F_max = F_z·μ·μ_r·λ(F_z/2) under its static load and its downforce at v.
    pub fn cornering_stiffness(&self, speed: f64, friction: f64) -> [f64; 2] {
        let v2 = speed * speed;
        [0, 1].map(|k| {
            let fz = self.static_load[k] + self.downforce_per_v2(speed)[k] * v2;
            let tyre = &self.tyres[k];
            tyre.axle_max_force(fz, friction) * tyre.b * tyre.c
        })
    }

    /// The weights of the front and rear axles' spin in the drive speed the gearbox reads.
    pub fn driven(&self) -> [f64; 2] {
        self.driven
    }

    /// The slip at which ABS and traction control start easing, per axle.
    pub fn aid_threshold(&self) -> [f64; 2] {
        self.aid_threshold
    }

    /// The gearbox's shift points.
    pub fn shift_map(&self) -> &ShiftMap {
        &self.shift_map
    }

    /// Standing still at (x, y) facing `yaw`, in first gear.
    pub fn at_rest(&self, x: f64, y: f64, yaw: f64) -> State {
        State {
            x,
            y,
            yaw,
            engine_speed: self.car.tickover,
            ..State::default()
        }
    }

    /// The wheels' speeds ω·R (m/s): the front axle's, the rear left's, the rear right's.
    pub fn wheel_speeds(&self, s: &State) -> [f64; 3] {
        [
            s.omega[0] * self.radius[0],
            s.omega[1] * self.radius[1],
            s.omega[2] * self.radius[1],
        ]
    }

    /// Sets the wheels' spins from their speeds ω·R (m/s), ordered as [`Vehicle::wheel_speeds`].
    pub fn set_wheel_speeds(&self, s: &mut State, speeds: [f64; 3]) {
        s.omega = [
            speeds[0] / self.radius[0],
            speeds[1] / self.radius[1],
            speeds[2] / self.radius[1],
        ];
    }

    /// The road's push per unit of the car's weight at forward speed vₓ: gravity's share on
    /// the grade φ and the banking β, and the vertical curvature's vₓ²κ_v (a crest unloads the
    /// car): n = cos φ·cos β + vₓ²·κ_v/g.
    #[inline]
    fn road_push(frame: &Frame, vx: f64) -> f64 {
        frame.cos_pitch * frame.cos_banking + vx * vx * frame.vertical_curvature / G
    }

    /// The rolling resistance coefficient on the road of `frame`: its surface's (simuv2), else
    /// the tyres', times the calibration's scale.
    #[inline]
    fn road_rolling(&self, frame: &Frame) -> f64 {
        frame.rolling_resistance.unwrap_or(self.rolling) * self.rolling_scale
    }

    /// Drag 0.645·Cx·A·v² along the velocity (|v|² = `v2`): its x component 0.645·Cx·A·v·vₓ.
    #[inline]
    fn drag_x(&self, v2: f64, vx: f64) -> f64 {
        self.drag_per_v2 * v2.sqrt() * vx
    }

    /// The tyres' longitudinal force per unit mass (m/s²) under which the body's vₓ changes
    /// at `dvx_dt`, as [`Vehicle::step`] balances them: Fₓ/m = v̇ₓ − v_y·r + (F_drag +
    /// F_roll)/m + g·sin φ, the drag 0.645·Cx·A·v·vₓ, the rolling resistance c_rr of the road
    /// under the axles' quasi-static loads and downforce, φ the grade. Not the speed's slope:
    /// in a slide v_y·r alone is some 2 m/s² (β = 0.1 rad at 30 m/s, r = 0.6 rad/s). Where a
    /// logged lap is picked up ([`super::replay`]), with [`Vehicle::under_way`].
    pub fn tyres_accel(
        &self,
        (vx, vy, yaw_rate): (f64, f64, f64),
        dvx_dt: f64,
        frame: &Frame,
    ) -> f64 {
        let v2 = vx * vx + vy * vy;
        let down = self.downforce_per_v2(v2.sqrt());
        let normal = Self::road_push(frame, vx);
        let loads = (self.static_load[0] + self.static_load[1]) * normal + (down[0] + down[1]) * v2;
        let roll = self.road_rolling(frame) * loads.max(0.0) * (vx / 0.5).clamp(-1.0, 1.0);
        dvx_dt - vy * yaw_rate + (self.drag_x(v2, vx) + roll) / self.car.mass + G * frame.sin_pitch
    }

    /// Under way at (x, y) facing `yaw`, with body velocities (vₓ, v_y), yaw rate r and the
    /// tyres' longitudinal force per unit mass `accel` (m/s²), in `gear` (0-based), as in a
    /// steady state: the wheels rolling at vₓ/R, the lagged load transfer settled (the
    /// longitudinal at `accel`, the lateral at the roll moment m·vₓ·r·(h_f·b + h_r·a)/L of
    /// the tyres' lateral forces shared by the lever rule), the clutch closed. Where a logged
    /// lap is picked up ([`super::replay`]).
    pub fn under_way(
        &self,
        (x, y, yaw): (f64, f64, f64),
        (vx, vy, yaw_rate): (f64, f64, f64),
        accel: f64,
        gear: usize,
    ) -> State {
        let [h_f, h_r] = self.car.axles.roll_centre;
        let l = self.a + self.b;
        let mut s = State {
            x,
            y,
            yaw,
            vx,
            vy,
            yaw_rate,
            omega: [
                vx / self.radius[0],
                vx / self.radius[1],
                vx / self.radius[1],
            ],
            ax: accel,
            roll: self.car.mass * vx * yaw_rate * (h_f * self.b + h_r * self.a) / l,
            yaw_sin_cos: yaw.sin_cos(),
            ..self.at_rest(x, y, yaw)
        };
        s.gearbox.gear = gear.min(self.car.gears.len().saturating_sub(1));
        s
    }

    /// The automatic gearbox's decision for the driver's throttle in [0, 1], taken at the
    /// driver's rate; also re-synchronises the incrementally rotated (sin ψ, cos ψ) with ψ.
    pub fn shift(&self, s: &mut State, throttle: f64) {
        s.yaw_sin_cos = s.yaw.sin_cos();
        let w = self.driven_omega(s);
        s.gearbox.update(&self.car, &self.shift_map, w, throttle);
    }

    /// The brake pedal in [0, 1] the driver applies for `brake` at a driver step, held until
    /// the next. A car the TORCS robot drives ([`Car::torcs_robot`]) gets the robot's ABS
    /// ([`crate::drive::aids::abs`]): one command for the four wheels, eased by each axle whose
    /// slide −(ω̄R − vₓ)/max(|vₓ|, v₀) passes its aid threshold. Another car's ABS eases each
    /// axle's brake inside the physics step ([`Vehicle::step`]).
    pub fn driver_brake(&self, s: &State, brake: f64) -> f64 {
        if !self.car.torcs_robot || brake <= 0.0 {
            return brake;
        }
        let inv_axle = 1.0 / s.vx.abs().max(SLIP_SPEED_FLOOR);
        let slide = |spin: f64, radius: f64| -(spin * radius - s.vx) * inv_axle;
        let slides = [
            slide(s.omega[0], self.radius[0]),
            slide(rear_omega(s), self.radius[1]),
        ];
        crate::drive::aids::abs::abs_brake(brake, slides, self.aid_threshold)
    }

    /// The launch clutch for the driver's throttle, taken at the driver's rate `dt` after
    /// its last step, after [`Vehicle::shift`]; for a car the TORCS robot drives
    /// ([`Car::torcs_robot`]; else the clutch stays closed), the robot's law
    /// ([`crate::drive::aids::launch::launch_clutch`]), which opens the clutch while pulling away in
    /// first gear and closes it over [`crate::drive::aids::launch::LAUNCH_TIME`] of throttle.
    pub fn clutch(&self, s: &mut State, throttle: f64, dt: f64) {
        let car = &self.car;
        if !car.torcs_robot {
            return;
        }
        let k = if self.driven[1] > 0.0 { 1 } else { 0 };
        let launch = crate::drive::aids::launch::LaunchCar {
            engine_speed: s.engine_speed,
            red_line: car.rev_limiter,
            first_ratio: car.gears[0] * car.final_drive,
            wheel_radius: self.radius[k],
            speed_x: s.vx,
        };
        s.clutch = crate::drive::aids::launch::launch_clutch(
            s.gearbox.gear,
            throttle,
            dt,
            &mut s.launch_time,
            &launch,
        );
    }

    /// Each wheel's ground, front left, front right, rear left, rear right: its surface's
    /// friction and rolling resistance coefficient (the tyres' where the surface gives none),
    /// and the bumps of a rough road under it ([`crate::track::Roughness::plain`] at
    /// t = l + w/2 from the road's right edge and the station s + a) with the road's kink there
    /// ([`Frame::kink_at`]`(a)`); `None` while all four stand on a smooth, unkinked road, as
    /// they do whenever the road has no verges of its own ([`Frame::has_verges`]) or the car
    /// is more than its reach inside both edges.
    ///
    /// As simuv2's `wheel.cpp` (`SimWheelUpdateRide`: `RtTrackGlobal2Local` of the wheel's
    /// position, then the segment's `surface->kFriction` and `kRollRes`), a wheel takes the
    /// surface under its centre: at body coordinates (x_w, y_w) = (a, ±y_f), (−b, ±y_r), with
    /// e = ψ − θ the car's heading against the road's, d = (X − Xᵢ, Y − Yᵢ) its position from the
    /// frame's station and t, n the road's tangent and left normal there, the wheel lies
    /// a = d·t + x_w·cos e − y_w·sin e along the road and l = d·n + x_w·sin e + y_w·cos e − κa²/2
    /// to the left of the centre line (the projection's second-order arc correction,
    /// [`crate::track::Track::project`]); past an edge by l − w/2 > 0 (or −l − w/2 on the
    /// right) it is on that side's [`crate::track::Verge`], border then side. A verge's own
    /// roughness is left out: smoothing the verges in the game changes none of 42 laps'
    /// outcomes, while adding them to cdbo's changes 10, 6 of them away from the game's
    /// (docs/results/torcs.md, "The road's roughness").
    #[inline]
    fn wheel_ground(&self, s: &State, f: &Frame) -> Option<[Ground; 4]> {
        // A rough or kinked road: the wheels on it bounce.
        let rough_road = (f.roughness.is_rough() || f.kinked) && self.corners.is_some();
        if !f.has_verges && !rough_road {
            return None;
        }
        let (along, lateral) = f.local(s.x, s.y);
        if self.inside_edges(f, along, lateral, 0.0) && !rough_road {
            return None;
        }
        let road_rolling = f.rolling_resistance.unwrap_or(self.rolling);
        let mut out = [Ground {
            friction: f.friction,
            rolling: road_rolling,
            bumps: Bumps::NONE,
        }; 4];
        let mut off = false;
        for (i, (a, l)) in self
            .wheel_places(s, f, along, lateral)
            .into_iter()
            .enumerate()
        {
            let excess = l.abs() - f.half_width;
            let verge = &f.verges[if l > 0.0 { 0 } else { 1 }];
            let off_road = if excess > 0.0 {
                verge.surface_at(excess)
            } else {
                None
            };
            match off_road {
                Some(surface) => {
                    out[i] = Ground {
                        friction: surface.friction,
                        rolling: surface.rolling_resistance.unwrap_or(self.rolling),
                        bumps: Bumps::NONE,
                    };
                    off = true;
                }
                None if rough_road => {
                    // simuv2's t: the distance from the road's right edge.
                    let mut bumps = if f.roughness.is_rough() {
                        f.roughness.plain(f.s + a, l + f.half_width)
                    } else {
                        Bumps::NONE
                    };
                    if f.kinked {
                        (bumps.kink, bumps.kink_slope) = f.kink_at(a);
                    }
                    out[i].bumps = bumps;
                }
                None => {}
            }
        }
        (off || rough_road).then_some(out)
    }

    /// Whether a wheel stands on a raised kerb ([`crate::track::Verge::kerb_height`], whose
    /// ramp cdbo's wheels do not climb), or would, moved `reserve` metres further out from the
    /// centre line, stand on slippery ground: a verge's border or side whose friction is below
    /// `fraction`·μ_road (grass, sand, gravel; a flat kerb as grippy as the road is not). Each
    /// wheel stands where the step finds its ground (`wheel_ground`); a road without verges of
    /// its own has none.
    pub fn wheel_near_slippery(&self, s: &State, f: &Frame, reserve: f64, fraction: f64) -> bool {
        if !f.has_verges {
            return false;
        }
        let (along, lateral) = f.local(s.x, s.y);
        if self.inside_edges(f, along, lateral, reserve) {
            return false;
        }
        let places = self.wheel_places(s, f, along, lateral);
        places.into_iter().any(|(_, l)| {
            let past_edge = l.abs() - f.half_width;
            let verge = &f.verges[if l > 0.0 { 0 } else { 1 }];
            let on_kerb =
                verge.kerb_height > 0.0 && past_edge > 0.0 && past_edge <= verge.border_width;
            let excess = past_edge + reserve;
            on_kerb
                || (excess > 0.0
                    && verge
                        .surface_at(excess)
                        .is_some_and(|ground| ground.friction < fraction * f.friction))
        })
    }

    /// Whether every wheel of a car at (`along`, `lateral`) from the frame's station stands
    /// more than `reserve` inside both edges, whatever its heading: its reach, and what the
    /// road's bend adds over it, short of the edge.
    #[inline]
    fn inside_edges(&self, f: &Frame, along: f64, lateral: f64, reserve: f64) -> bool {
        let far = along.abs() + self.reach;
        lateral.abs() + self.reach + reserve + 0.5 * f.curvature.abs() * far * far < f.half_width
    }

    /// Where each wheel's centre stands, front left, front right, rear left, rear right, the
    /// car at (`along`, `lateral`) from the frame's station: (a, l) along the road and left of
    /// the centre line, as [`Vehicle::wheel_ground`] places them.
    #[inline]
    fn wheel_places(&self, s: &State, f: &Frame, along: f64, lateral: f64) -> [(f64, f64); 4] {
        let (se, ce) = f.relative_heading(s.yaw_sin_cos);
        let [yf, yr] = self.car.axles.half_track;
        [(self.a, yf), (self.a, -yf), (-self.b, yr), (-self.b, -yr)].map(|(xw, yw)| {
            let a = along + xw * ce - yw * se;
            (a, lateral + xw * se + yw * ce - 0.5 * f.curvature * a * a)
        })
    }

    fn driven_omega(&self, s: &State) -> f64 {
        self.driven[0] * s.omega[0] + self.driven[1] * rear_omega(s)
    }

    /// Advances the state by `dt` seconds on the road described by `frame`.
    pub fn step(&self, s: &mut State, c: &Controls, frame: &Frame, dt: f64) {
        let car = &self.car;
        let m = car.mass;
        let v2 = s.vx * s.vx + s.vy * s.vy;
        let per_v2 = self.downforce_per_v2(v2.sqrt());
        let down = [per_v2[0] * v2, per_v2[1] * v2];
        let normal = Self::road_push(frame, s.vx);
        let transfer = self.transfer_per_accel * s.ax - self.wing_pitch_per_v2 * v2;
        let fz = [
            (self.static_load[0] * normal - transfer + down[0]).max(0.0),
            (self.static_load[1] * normal + transfer + down[1]).max(0.0),
        ];
        // The wheels' loads, left and right: the roll moment moves ΔF_a from each axle's inner
        // wheel to its outer one (the left wheel is the inner one while the roll moment is
        // positive, in a left-hand corner).
        let wheel_loads = |k: usize| {
            let shift = self.roll_share[k] * s.roll;
            [
                (0.5 * fz[k] - shift).max(0.0),
                (0.5 * fz[k] + shift).max(0.0),
            ]
        };
        let (front_loads, rear_loads) = (wheel_loads(0), wheel_loads(1));
        // Each wheel's surface: the road's, or a verge's past the road's edge.
        let ground = self.wheel_ground(s, frame);
        let mut friction = match &ground {
            None => [frame.friction; 4],
            Some(w) => w.map(|g| g.friction),
        };
        // The wheels' bounce over rough ground and the road's kinks takes some of their grip.
        if let Some(corners) = &self.corners {
            let loads = [front_loads[0], front_loads[1], rear_loads[0], rear_loads[1]];
            for (i, f) in friction.iter_mut().enumerate() {
                let bumps = ground.map_or(Bumps::NONE, |w| w[i].bumps);
                if bumps.any() || !s.bounce[i].settled() {
                    let k = i / 2;
                    *f *= bounce::step(
                        &mut s.bounce[i],
                        &corners[k],
                        loads[i],
                        &bumps,
                        s.vx,
                        dt,
                        &self.tyres[k],
                    );
                }
            }
        }

        // Wheel-frame velocities of the front (steered) axle and the rear wheels, the left one
        // at y = +y_r (simuv2's `car.cpp`: vₓ − r·y).
        let front_lat = s.vy + self.a * s.yaw_rate;
        let turn = self.car.axles.half_track[1] * s.yaw_rate;
        let vt_rear = [s.vx - turn, s.vx + turn];
        let vl_rear = s.vy - self.b * s.yaw_rate;
        // 1 / max(|v_t|, v₀), the longitudinal slip's denominator, and 1 / max(|v|, v₀), the
        // lateral slip's (s_y = sin of the slip angle), per wheel.
        let inv_rear = [
            1.0 / vt_rear[0].abs().max(SLIP_SPEED_FLOOR),
            1.0 / vt_rear[1].abs().max(SLIP_SPEED_FLOOR),
        ];
        let inv_speed_rear = vt_rear.map(|vt| 1.0 / vt.hypot(vl_rear).max(SLIP_SPEED_FLOOR));
        // An axle as the robot reads it: its wheels' mean spin against vₓ.
        let inv_axle = 1.0 / s.vx.abs().max(SLIP_SPEED_FLOOR);

        // Drive torque. A car the TORCS robot drives gets the robot's traction control in
        // every gear, on the driven wheels' mean slip speed ωR − vₓ
        // ([`crate::drive::aids::traction`]), as the game's car does: with the rear wheels modelled
        // one by one, the inner wheel's spin on a corner's exit is the tyres' own. Another car
        // has its throttle eased while the driven axle's combined slip, with the wheels
        // spinning faster than the road, passes the aid threshold.
        let mut throttle = c.throttle();
        let k = if self.driven[1] > 0.0 { 1 } else { 0 };
        let (spin_speed, lateral) = if k == 1 {
            (rear_omega(s) * self.radius[1] - s.vx, vl_rear * inv_axle)
        } else {
            (s.omega[0] * self.radius[0] - s.vx, front_lat * inv_axle)
        };
        let spin = spin_speed * inv_axle;
        let combined2 = spin * spin + lateral * lateral;
        let threshold = self.aid_threshold[k];
        if self.car.torcs_robot {
            throttle = crate::drive::aids::traction::traction_throttle(throttle, spin_speed);
        } else if spin > 0.0 && combined2 > threshold * threshold {
            throttle *= (2.0 - combined2.sqrt() / threshold).clamp(0.0, 1.0);
        }
        // A slipping clutch (simuv2's transmission.cpp and engine.cpp): the engine turns at
        // its own speed ω_e, unloaded by the clutch, and the wheels get its torque
        // T_e(ω_e)·g·min(3τ, 1) for the clutch's transfer τ = 1 − c; closed (τ = 1), ω_e
        // follows the wheels as below.
        let transfer = 1.0 - s.clutch;
        let slipping = transfer < 1.0 && s.gearbox.gear == 0;
        let mut engine_torque = 0.0;
        let (drive_torque, engine_speed) = if slipping {
            let w = s.engine_speed.min(car.rev_limiter);
            engine_torque = car.part_throttle_torque(self.engine_map.torque(w), throttle, w);
            let ratio = s.gearbox.ratio(car);
            let torque = if s.gearbox.shifting > 0.0 {
                0.0
            } else {
                engine_torque * ratio * (3.0 * transfer).min(1.0)
            };
            (torque, w)
        } else {
            s.gearbox
                .wheel_torque(car, &self.engine_map, throttle, self.driven_omega(s))
        };
        s.engine_speed = engine_speed;
        let drive_torque = if s.gearbox.gear == 0 {
            drive_torque * self.launch_scale
        } else {
            drive_torque
        };
        s.gearbox.shifting = (s.gearbox.shifting - dt).max(0.0);

        // The front wheels: one spin for both, each steered, loaded and gripping on its own;
        // the inner wheel turned by δ, the outer by simuv2's Ackermann angle (`steer.cpp`),
        // tan δ_o = L·tan|δ|/(L + T·tan|δ|), T = y_f + y_r.
        let (sin_d, cos_d) = c.steer_sin_cos;
        let tan_d = (sin_d / cos_d).abs();
        let (l, [y_f, y_r]) = (self.car.wheelbase, self.car.axles.half_track);
        let tan_o = l * tan_d / (l + (y_f + y_r) * tan_d);
        let cos_o = 1.0 / (1.0 + tan_o * tan_o).sqrt();
        let outer = ((tan_o * cos_o).copysign(sin_d), cos_o);
        // Left first: the left wheel is the inner one in a left-hand turn (δ > 0).
        let angles = if sin_d >= 0.0 {
            [(sin_d, cos_d), outer]
        } else {
            [outer, (sin_d, cos_d)]
        };
        let (front_x, front_y, front_moment) = {
            let tyre = &self.tyres[0];
            let r = self.radius[0];
            let wheel = |i: usize| {
                let (sn, cs) = angles[i];
                let vt = s.vx * cs + front_lat * sn;
                let vl = -s.vx * sn + front_lat * cs;
                let inv = 1.0 / vt.abs().max(SLIP_SPEED_FLOOR);
                let fmax = tyre.wheel_max_force(front_loads[i], friction[i]);
                let sx = (s.omega[0] * r - vt) * inv;
                let sy = -vl / vt.hypot(vl).max(SLIP_SPEED_FLOOR);
                (tyre.forces(sx, sy, fmax), fmax, inv)
            };
            let wheels = [wheel(0), wheel(1)];
            // ABS: ease the pressure while the axle slides backwards past the threshold.
            let mut brake = c.brake() * self.max_brake[0];
            let threshold = self.aid_threshold[0];
            let slide = -(s.omega[0] * r - s.vx) * inv_axle;
            if !car.torcs_robot && slide > threshold {
                brake *= (2.0 - slide / threshold).clamp(0.0, 1.0);
            }
            // Implicit step of I·dω/dt = T − T_b·sgn ω − R·ΣFₓ(ω), with Fₓ linear in ω.
            let dfx_domega: f64 = wheels
                .iter()
                .map(|(f, _, inv)| (f.dfx_dsx * r * inv).max(0.0))
                .sum();
            let inertia = self.wheel_inertia[0];
            let torque = self.driven[0] * drive_torque - r * (wheels[0].0.fx + wheels[1].0.fx);
            let free = torque - brake * s.omega[0].signum() * f64::from(s.omega[0] != 0.0);
            let mut new_omega = s.omega[0] + dt * free / (inertia + dt * r * dfx_domega);
            // Brakes can stop a wheel but never spin it backwards.
            if (brake > 0.0 && new_omega * s.omega[0] < 0.0)
                || (s.omega[0] == 0.0 && brake > torque.abs())
            {
                new_omega = 0.0;
            }
            let domega = new_omega - s.omega[0];
            s.omega[0] = new_omega;
            // Forces at the new spin, to first order, kept inside the grip budget, turned
            // into the body's frame.
            let mut body = [(0.0, 0.0); 2];
            for (i, (f, fmax, inv)) in wheels.iter().enumerate() {
                let dsx = domega * r * inv;
                let (x, y) = (f.fx + f.dfx_dsx * dsx, f.fy + f.dfy_dsx * dsx);
                let cap = fmax * tyre.force_cap;
                let (x, y) = if x * x + y * y > cap * cap {
                    scale_to_budget(x, y, cap)
                } else {
                    (x, y)
                };
                let (sn, cs) = angles[i];
                body[i] = (x * cs - y * sn, x * sn + y * cs);
            }
            (
                body[0].0 + body[1].0,
                body[0].1 + body[1].1,
                self.car.axles.half_track[0] * (body[1].0 - body[0].0),
            )
        };

        let (fx_rear, fy_rear) = self.rear_wheels(
            s,
            c.brake(),
            self.driven[1] * drive_torque,
            &RearWheels {
                loads: rear_loads,
                vt: vt_rear,
                vl: vl_rear,
                inv_denom: inv_rear,
                inv_speed: inv_speed_rear,
                inv_axle,
            },
            [friction[2], friction[3]],
            dt,
        );

        if slipping {
            // ω_e ← ω_axle·g·(1 − k) + (ω_e + T_e·dt/I_e)·k, k = (1 − τ⁴)^(dt/T_g), within idle
            // and the revs maximum; free (τ ≤ 0.01), ω_e + T_e·dt/I_e. simuv2's `engine.cpp`
            // blends by τ⁴ at each of its own steps T_g ([`GAME_STEP`]): k is that blend over
            // this step's dt/T_g of them.
            let free = s.engine_speed + engine_torque * dt / car.engine_inertia;
            s.engine_speed = if transfer > 0.01 {
                let keep = (1.0 - transfer.powi(4)).powf(dt / GAME_STEP);
                let w = self.driven_omega(s) * s.gearbox.ratio(car) * (1.0 - keep) + free * keep;
                w.clamp(car.tickover, car.revs_max)
            } else {
                free
            };
        }

        // Body forces and moments.
        // Rolling resistance opposes motion; sgn vₓ is smoothed over ±0.5 m/s for standing starts.
        // The road's coefficient where the track gives one (simuv2), else the tyres'.
        // A wheel on a verge rolls against its surface's coefficient: Σᵢ c_rr,i·F_z,i, taken as
        // the road's c_rr·(F_zf + F_zr) plus Σᵢ (c_rr,i − c_rr)·F_z,i.
        let c_rr = self.road_rolling(frame);
        let mut rolling_force = c_rr * (fz[0] + fz[1]);
        if let Some(w) = &ground {
            let loads = [front_loads[0], front_loads[1], rear_loads[0], rear_loads[1]];
            for (i, g) in w.iter().enumerate() {
                rolling_force += (g.rolling * self.rolling_scale - c_rr) * loads[i];
            }
        }
        let roll = rolling_force * (s.vx / 0.5).clamp(-1.0, 1.0);
        let drag = self.drag_x(v2, s.vx);
        let tyres_x = front_x + fx_rear[0] + fx_rear[1];
        let force_x = tyres_x - drag - roll - m * G * frame.sin_pitch;
        // cos(ψ − θ) of the car's yaw against the road's heading.
        let (sy, cy) = s.yaw_sin_cos;
        let along = cy * frame.cos_heading + sy * frame.sin_heading;
        let rear_y = fy_rear[0] + fy_rear[1];
        let force_y = front_y + rear_y - m * G * frame.sin_banking * along;
        // The rear wheels' longitudinal forces at ±y_r turn the car too (simuv2's `car.cpp`:
        // M_z = Σ −Fₓ·y + Fᵧ·x).
        let moment = self.a * front_y - self.b * rear_y
            + front_moment
            + self.car.axles.half_track[1] * (fx_rear[1] - fx_rear[0]);

        let moment = moment - self.rolling_yaw_moment(rolling_force, s.yaw_rate);

        let inv_m = self.inv_mass;
        let ax = force_x * inv_m;
        s.vx += dt * (ax + s.vy * s.yaw_rate);
        s.vy += dt * (force_y * inv_m - s.vx * s.yaw_rate);
        s.yaw_rate += dt * moment * self.inv_yaw_inertia;
        s.yaw += dt * s.yaw_rate;
        // Keep the yaw in (−π, π]: cheap trigonometry, and no drift of precision over laps.
        if s.yaw > std::f64::consts::PI {
            s.yaw -= std::f64::consts::TAU;
        } else if s.yaw <= -std::f64::consts::PI {
            s.yaw += std::f64::consts::TAU;
        }
        // Rotate (sin ψ, cos ψ) by the step's dψ: for |dψ| ≤ 0.01 rad (yaw rates to 2.5 rad/s
        // at 4 ms) the series to dψ⁵ is exact in double precision, to 0.02 rad (a spin at
        // 5 rad/s) within 1e-13; the driver step re-synchronises it with sin_cos(ψ).
        let d = dt * s.yaw_rate;
        let d2 = d * d;
        let (sd, cd) = (
            d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0)),
            1.0 - d2 / 2.0 * (1.0 - d2 / 12.0),
        );
        let (sy0, cy0) = s.yaw_sin_cos;
        s.yaw_sin_cos = (sy0 * cd + cy0 * sd, cy0 * cd - sy0 * sd);
        let (sin_y, cos_y) = s.yaw_sin_cos;
        s.x += dt * (s.vx * cos_y - s.vy * sin_y);
        s.y += dt * (s.vx * sin_y + s.vy * cos_y);
        // Load transfer follows the tyres' forces with a short lag (the body's pitch and roll).
        s.ax += (tyres_x * inv_m - s.ax) * (dt * PITCH_RATE).min(1.0);
        let [h_f, h_r] = self.car.axles.roll_centre;
        let roll_moment = front_y * h_f + rear_y * h_r;
        s.roll += (roll_moment - s.roll) * (dt * ROLL_RATE).min(1.0);
    }
}

/// The rear wheels' loads and wheel-frame velocities at a step.
struct RearWheels {
    /// Normal loads of the left and right wheels (N).
    loads: [f64; 2],
    /// Tangential velocities (m/s).
    vt: [f64; 2],
    /// Lateral velocity, the same for both (m/s).
    vl: f64,
    /// 1 / max(|v_t|, v₀) of each wheel.
    inv_denom: [f64; 2],
    /// 1 / max(|v|, v₀) of each wheel, |v| = √(v_t² + v_l²).
    inv_speed: [f64; 2],
    /// 1 / max(|vₓ|, v₀) of the car.
    inv_axle: f64,
}

impl Vehicle {
    /// Steps the rear wheels' spins under the drive torque `drive` at the axle (N·m), the
    /// brake pedal and their tyres' forces, and returns their forces (Fₓ and Fᵧ of the left
    /// and right wheels, N), as simuv2's `differential.cpp` drives them:
    ///
    /// - **Spool** (and a limited slip past its locking torque, T > T_lock or
    ///   T < −T_lock,brake): one shaft, 2I·dω/dt = T − Σ R·Fₓ,i − Σ T_b,i, both wheels at
    ///   their mean spin.
    /// - **Limited slip** below it: the wheels' speed ratio ρ = |ω₀ − ω₁|/(|ω₀| + |ω₁|) is held
    ///   to ρ_max = ρ_s·(1 − |T|/T_lock) (ρ_s the `max slip bias`, T_lock of the torque's sign)
    ///   by moving both spins (ρ − ρ_max)·(|ω₀| + |ω₁|)/2 towards each other, and the torque
    ///   is split T·(1 ± (ρ − ρ_max))/2, more to the slower wheel under drive; then as free.
    /// - **Free**: each wheel gets T_i plus simuv2's spider torque, I·dω_i/dt = T_i +
    ///   (τ_j − τ_i)/2 − τ_i − T_b,i with τ = R·Fₓ the tyre's reaction (T_i = T/2).
    /// - A rear axle without drive rolls free: I·dω_i/dt = −τ_i − T_b,i.
    ///
    /// Integrated implicitly in the spins (each τ linear in its wheel's ω, a 2×2 system),
    /// stable at the 4 ms step where simuv2 steps explicitly at 2 ms. ABS eases both brakes
    /// on the axle's mean slip (ω̄R − vₓ)/max(|vₓ|, v₀), except on a car the TORCS robot
    /// drives, whose brake the driver has eased already ([`Vehicle::driver_brake`]).
    fn rear_wheels(
        &self,
        s: &mut State,
        brake_pedal: f64,
        drive: f64,
        w: &RearWheels,
        friction: [f64; 2],
        dt: f64,
    ) -> ([f64; 2], [f64; 2]) {
        let tyre = &self.tyres[1];
        let r = self.radius[1];
        let inertia = self.wheel_inertia[1];
        let diff = &self.car.differential;
        let mut omega = [s.omega[1], s.omega[2]];
        // The differential's mode, its torque split and its speed constraint.
        let driven = self.driven[1] > 0.0;
        let rigid = driven
            && match diff.kind {
                DiffKind::Spool => true,
                DiffKind::LimitedSlip => {
                    drive > diff.lock_torque || drive < -diff.lock_brake_torque
                }
                DiffKind::Free => false,
            };
        let mut split = [0.5 * drive; 2];
        let spider = if driven { 0.5 } else { 0.0 };
        if rigid {
            let mean = 0.5 * (omega[0] + omega[1]);
            omega = [mean; 2];
        } else if driven && diff.kind == DiffKind::LimitedSlip {
            let sum = omega[0].abs() + omega[1].abs();
            if sum > 0.0 {
                let ratio = (omega[0] - omega[1]).abs() / sum;
                let lock = if drive >= 0.0 {
                    diff.lock_torque
                } else {
                    diff.lock_brake_torque
                };
                let max = diff.slip_max * (1.0 - drive.abs() / lock);
                if ratio > max {
                    let excess = ratio - max;
                    let delta = excess * 0.5 * sum;
                    // The faster wheel slows, the slower speeds up, and the torque favours
                    // the slower one under drive (the faster one under the engine brake).
                    let faster = if omega[0] > omega[1] { 0 } else { 1 };
                    omega[faster] -= delta;
                    omega[1 - faster] += delta;
                    let bias = excess * drive.signum();
                    split[faster] = 0.5 * drive * (1.0 - bias);
                    split[1 - faster] = 0.5 * drive * (1.0 + bias);
                }
            }
        }

        // ABS on the axle's mean slip.
        let mut brake = brake_pedal * self.max_brake[1];
        let threshold = self.aid_threshold[1];
        let slide = -(0.5 * (omega[0] + omega[1]) * r - s.vx) * w.inv_axle;
        if !self.car.torcs_robot && slide > threshold {
            brake *= (2.0 - slide / threshold).clamp(0.0, 1.0);
        }

        // Tyre forces at the spins, their reaction torques τ and dτ/dω.
        let forces = [0, 1].map(|i| {
            let fmax = tyre.wheel_max_force(w.loads[i], friction[i]);
            let sx = (omega[i] * r - w.vt[i]) * w.inv_denom[i];
            let sy = -w.vl * w.inv_speed[i];
            (tyre.forces(sx, sy, fmax), fmax)
        });
        let tau = [r * forces[0].0.fx, r * forces[1].0.fx];
        let dtau = [0, 1].map(|i| (forces[i].0.dfx_dsx * r * r * w.inv_denom[i]).max(0.0));
        let brake_torque = [0, 1].map(|i| brake * omega[i].signum() * f64::from(omega[i] != 0.0));
        let step = if rigid {
            let d = dt * (drive - tau[0] - tau[1] - brake_torque[0] - brake_torque[1])
                / (2.0 * inertia + dt * (dtau[0] + dtau[1]));
            [d; 2]
        } else {
            // (I + dt·d_i·(1 + h))·Δ_i − dt·h·d_j·Δ_j = dt·(T_i + h·(τ_j − τ_i) − τ_i − T_b,i),
            // h the spider's half.
            let h = spider;
            let rhs = [0, 1].map(|i| {
                let j = 1 - i;
                dt * (split[i] + h * (tau[j] - tau[i]) - tau[i] - brake_torque[i])
            });
            let a = [0, 1].map(|i| inertia + dt * dtau[i] * (1.0 + h));
            let b = [0, 1].map(|i| -dt * h * dtau[i]);
            let det = a[0] * a[1] - b[0] * b[1];
            [
                (rhs[0] * a[1] - b[1] * rhs[1]) / det,
                (a[0] * rhs[1] - b[0] * rhs[0]) / det,
            ]
        };
        let mut fx = [0.0; 2];
        let mut fy = [0.0; 2];
        for i in 0..2 {
            let (f, fmax) = forces[i];
            let mut new_omega = omega[i] + step[i];
            // Brakes can stop a wheel but never spin it backwards.
            let torque = split[i] - tau[i];
            if (brake > 0.0 && new_omega * omega[i] < 0.0)
                || (omega[i] == 0.0 && brake > torque.abs())
            {
                new_omega = 0.0;
            }
            let dsx = (new_omega - omega[i]) * r * w.inv_denom[i];
            s.omega[1 + i] = new_omega;
            let (x, y) = (f.fx + f.dfx_dsx * dsx, f.fy + f.dfy_dsx * dsx);
            let cap = fmax * tyre.force_cap;
            (fx[i], fy[i]) = if x * x + y * y > cap * cap {
                scale_to_budget(x, y, cap)
            } else {
                (x, y)
            };
        }
        (fx, fy)
    }
}

/// The rear wheels' mean spin (rad/s).
#[inline]
pub fn rear_omega(s: &State) -> f64 {
    0.5 * (s.omega[1] + s.omega[2])
}

/// (x, y) scaled to the length `fmax`. Rarely needed, so kept out of line: the hot path
/// then skips its square root and division instead of computing them speculatively.
#[cold]
#[inline(never)]
fn scale_to_budget(x: f64, y: f64, fmax: f64) -> (f64, f64) {
    let scale = fmax / (x * x + y * y).sqrt();
    (x * scale, y * scale)
}

/// The step of TORCS's simuv2 (s; `RCM_MAX_DT_SIMU`), at which its slipping clutch blends the
/// engine's speed with the wheels'.
const GAME_STEP: f64 = 0.002;

/// Speed step (m/s) of the table of downforce per v².
const DOWNFORCE_SPEED_STEP: f64 = 0.5;
/// Steps of the table: up to 150 m/s.
const DOWNFORCE_SPEEDS: usize = 300;

/// 1 / time constant of the longitudinal load transfer (1/s): the pitch dynamics follow
/// the acceleration with a 50 ms lag.
const PITCH_RATE: f64 = 20.0;
/// 1 / time constant of the lateral load transfer (1/s): simuv2's body rolls against springs
/// and dampers that, for car1-trb1 (κ = 1.17 MN/m a wheel, slow bump and rebound some
/// 0.08 MN·s/m), settle it over c/κ ≈ 70 ms.
const ROLL_RATE: f64 = 14.0;

#[cfg(test)]
mod tests {
    use super::*;

    /// A level straight's frame.
    fn level() -> Frame {
        let t = crate::track::Track::from_pieces(
            "straight",
            "test",
            &[crate::track::Piece::flat(500.0, 0.0)],
            vec![],
        );
        *t.frame(0)
    }

    /// The car mirrored: steering, lateral velocity, yaw rate, roll moment and the rear wheels
    /// swapped left for right give the mirrored step, to the last bits (the Ackermann wheel,
    /// the wheels' loads and the rear wheels' yaw moment take the right sides), for a limited
    /// slip, a spool and a free differential, under drive and under the brakes.
    #[test]
    fn a_left_hand_turn_mirrors_a_right_hand_one() {
        for kind in [DiffKind::LimitedSlip, DiffKind::Spool, DiffKind::Free] {
            let mut car = Car::spirit_300();
            car.differential.kind = kind;
            let v = Vehicle::new(&car);
            let frame = level();
            for (throttle, brake) in [(0.8, 0.0), (0.0, 0.6)] {
                let mut left = v.at_rest(0.0, 0.0, 0.0);
                left.vx = 30.0;
                left.vy = 0.4;
                left.yaw_rate = 0.5;
                left.roll = 2000.0;
                left.omega = [30.0 / v.radius[0], 31.0 / v.radius[1], 32.0 / v.radius[1]];
                left.yaw_sin_cos = left.yaw.sin_cos();
                v.shift(&mut left, throttle);
                let mut right = left;
                right.vy = -left.vy;
                right.yaw_rate = -left.yaw_rate;
                right.roll = -left.roll;
                right.omega = [left.omega[0], left.omega[2], left.omega[1]];
                for _ in 0..50 {
                    v.step(
                        &mut left,
                        &Controls::new(0.1, throttle, brake),
                        &frame,
                        0.004,
                    );
                    v.step(
                        &mut right,
                        &Controls::new(-0.1, throttle, brake),
                        &frame,
                        0.004,
                    );
                }
                let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(1.0);
                assert!(close(left.vx, right.vx), "{kind:?}: {left:?} {right:?}");
                assert!(close(left.vy, -right.vy), "{kind:?}: {left:?} {right:?}");
                assert!(close(left.yaw_rate, -right.yaw_rate), "{kind:?}");
                assert!(close(left.roll, -right.roll), "{kind:?}");
                assert!(close(left.omega[1], right.omega[2]), "{kind:?}");
                assert!(close(left.omega[2], right.omega[1]), "{kind:?}");
                assert!(left.yaw_rate > 0.0 && left.roll > 0.0, "{kind:?}: {left:?}");
            }
        }
    }

    /// A wheel takes the surface under its centre: on a straight 12 m wide with a 2 m border
    /// of friction 0.4 on the left and a sand side of 0.6 on the right, a car whose centre is
    /// 5.5 m left of the centre line has its left wheels (0.7 to 0.8 m further out) on the
    /// border and its right ones on the road; turned 90° to the left, its front wheels are on
    /// the border and its rear ones on the road; 6.5 m right, its right wheels are on the
    /// side; on the centre line, or on a road without verges, all four are on the road.
    #[test]
    fn each_wheel_takes_the_surface_under_it() {
        use crate::track::{Piece, Surface, Track, Verge};
        let border = Surface {
            friction: 0.4,
            rolling_resistance: Some(0.05),
            ..Surface::PLAIN
        };
        let sand = Surface {
            friction: 0.6,
            ..Surface::PLAIN
        };
        let piece = Piece {
            verges: [
                Verge {
                    border_width: 2.0,
                    border,
                    ..Verge::NONE
                },
                Verge {
                    side_width: 5.0,
                    side: sand,
                    ..Verge::NONE
                },
            ],
            ..Piece::flat(500.0, 0.0)
        };
        let t = Track::from_pieces("verges", "test", &[piece], vec![]);
        let frame = *t.frame(100);
        let v = Vehicle::new(&Car::spirit_300());
        let at = |y: f64, yaw: f64| {
            let mut s = v.at_rest(100.0, y, yaw);
            s.yaw_sin_cos = yaw.sin_cos();
            v.wheel_ground(&s, &frame)
                .map(|w| w.map(|g| (g.friction, g.rolling)))
        };
        let (road, rr) = (1.0, v.rolling);
        assert_eq!(at(0.0, 0.0), None);
        assert_eq!(
            at(5.5, 0.0),
            Some([(0.4, 0.05), (road, rr), (0.4, 0.05), (road, rr)])
        );
        assert_eq!(
            at(5.0, std::f64::consts::FRAC_PI_2),
            Some([(0.4, 0.05), (0.4, 0.05), (road, rr), (road, rr)])
        );
        assert_eq!(
            at(-6.5, 0.0),
            Some([(road, rr), (0.6, rr), (road, rr), (0.6, rr)])
        );
        let plain = Track::from_pieces("plain", "test", &[Piece::flat(500.0, 0.0)], vec![]);
        let mut s = v.at_rest(100.0, 5.5, 0.0);
        s.yaw_sin_cos = (0.0, 1.0);
        assert!(v.wheel_ground(&s, plain.frame(100)).is_none());
    }

    /// The reserve's wheels keep off slippery ground and raised kerbs, and nothing else: on a
    /// straight 12 m wide with a flat kerb 1.5 m wide as grippy as the road then grass (0.4) on
    /// the left, and a raised kerb 1 m wide then run-off asphalt on the right, a car heading
    /// along the road with its wheels y_w out from its centre is too near once y + y_w + r
    /// passes 6 + 1.5 on the left, and once −y + y_w passes 6 on the right (a wheel on the
    /// kerb, whatever the reserve), to the millimetre; past the kerb, on the asphalt, it is
    /// not; without verges, never.
    #[test]
    fn the_reserve_keeps_the_wheels_off_grass_and_raised_kerbs() {
        use crate::track::{Piece, Surface, Track, Verge};
        let grass = Surface {
            friction: 0.4,
            ..Surface::PLAIN
        };
        let piece = Piece {
            verges: [
                Verge {
                    border_width: 1.5,
                    side_width: 5.0,
                    side: grass,
                    ..Verge::NONE
                },
                Verge {
                    border_width: 1.0,
                    kerb_height: 0.1,
                    side_width: 5.0,
                    ..Verge::NONE
                },
            ],
            ..Piece::flat(500.0, 0.0)
        };
        let t = Track::from_pieces("verges", "test", &[piece], vec![]);
        let frame = *t.frame(100);
        let v = Vehicle::new(&Car::spirit_300());
        let wheel = v.car.axles.half_track[0].max(v.car.axles.half_track[1]);
        let near = |frame: &Frame, y: f64, reserve: f64| {
            let mut s = v.at_rest(100.0, y, 0.0);
            s.yaw_sin_cos = (0.0, 1.0);
            v.wheel_near_slippery(&s, frame, reserve, 0.8)
        };
        for reserve in [0.0, 0.25, 1.0] {
            let left = 7.5 - wheel - reserve;
            assert!(!near(&frame, left - 1e-3, reserve), "r = {reserve}");
            assert!(near(&frame, left + 1e-3, reserve), "r = {reserve}");
            let right = 6.0 - wheel;
            assert!(!near(&frame, -right + 1e-3, reserve), "r = {reserve}");
            assert!(near(&frame, -right - 1e-3, reserve), "r = {reserve}");
            assert!(near(&frame, -right - 0.99, reserve), "r = {reserve}");
        }
        // Every wheel past the raised kerb, on the asphalt beyond it.
        assert!(!near(&frame, -(7.0 + wheel + 0.1), 0.25));
        let plain = Track::from_pieces("plain", "test", &[Piece::flat(500.0, 0.0)], vec![]);
        assert!(!near(plain.frame(100), 7.0, 0.25));
    }

    /// The rolling resistance turns against the yaw as simuv2's `car.cpp` has it. One 4 ms
    /// step of a car yawing at 0.6 rad/s on a road of c_rr = 0.01 loses R·L/2·dt/I_z more yaw
    /// rate than on a road without rolling resistance, R = c_rr·(F_zf + F_zr) its rolling
    /// resistance; a yaw slower than R·L/(2·I_z) loses r·dt, dying away over a second.
    #[test]
    fn the_rolling_resistance_turns_against_the_yaw() {
        let v = Vehicle::new(&Car::spirit_300());
        let (speed, c_rr, dt) = (30.0, 0.01, 0.004);
        let yaw_rate_after = |rolling: f64, yaw_rate: f64| {
            let mut frame = level();
            frame.rolling_resistance = Some(rolling);
            let mut s = v.at_rest(0.0, 0.0, 0.0);
            s.vx = speed;
            s.yaw_rate = yaw_rate;
            s.omega = [
                speed / v.radius[0],
                speed / v.radius[1],
                speed / v.radius[1],
            ];
            v.step(&mut s, &Controls::default(), &frame, dt);
            s.yaw_rate
        };
        let down = v.downforce_per_v2(speed);
        let loads = v.static_load[0] + v.static_load[1] + (down[0] + down[1]) * speed * speed;
        let turning = 0.5 * c_rr * loads * v.car.wheelbase * v.inv_yaw_inertia;
        let (fast, slow) = (0.6, 0.5 * turning);
        assert!(turning < fast, "{turning}");
        let lost = yaw_rate_after(0.0, fast) - yaw_rate_after(c_rr, fast);
        assert!(
            (lost - turning * dt).abs() < 1e-12,
            "{lost} against {}",
            turning * dt
        );
        let lost = yaw_rate_after(0.0, slow) - yaw_rate_after(c_rr, slow);
        assert!(
            (lost - slow * dt).abs() < 1e-12,
            "{lost} against {}",
            slow * dt
        );
    }

    /// The slipping launch clutch blends the engine's speed with the wheels' at the game's own
    /// 2 ms step, whatever cdbo's: pulling away at half throttle with the clutch 70 % open
    /// (τ = 0.3), the engine's speed after 0.15 s at steps of 2 and 4 ms agrees within 1 %
    /// (blending by τ⁴ once per 4 ms step, as before session 33, left it 23 % higher).
    #[test]
    fn the_launch_clutch_blends_at_the_games_step() {
        let v = Vehicle::new(&Car::spirit_300());
        let frame = level();
        let engine_after = |dt: f64| {
            let mut s = v.at_rest(0.0, 0.0, 0.0);
            s.clutch = 0.7;
            for _ in 0..(0.15 / dt).round() as usize {
                v.step(&mut s, &Controls::new(0.0, 0.5, 0.0), &frame, dt);
            }
            s.engine_speed
        };
        let (fine, coarse) = (engine_after(GAME_STEP), engine_after(2.0 * GAME_STEP));
        assert!(fine > 1.05 * v.car.tickover, "{fine}: the engine revs");
        assert!(
            (coarse / fine - 1.0).abs() < 0.01,
            "{coarse} against {fine}"
        );
    }

    /// The lateral load transfer takes the roll moment up: the axles' transfers ΔF_a at ±y_a
    /// give back M (Σ 2·ΔF_a·y_a = M), shared as the rates in roll times the tracks.
    #[test]
    fn the_wheels_take_up_the_roll_moment() {
        let car = Car::spirit_300();
        let v = Vehicle::new(&car);
        let (y, k) = (car.axles.half_track, car.axles.roll_rate);
        let moment = 2.0 * (v.roll_share[0] * y[0] + v.roll_share[1] * y[1]);
        assert!((moment - 1.0).abs() < 1e-12, "{moment}");
        let ratio = v.roll_share[0] / v.roll_share[1];
        assert!((ratio - k[0] * y[0] / (k[1] * y[1])).abs() < 1e-12);
    }

    /// Through a spool the rear wheels turn as one; through a limited slip under a drive
    /// torque T below its locking torque their speed ratio ends within ρ_s·(1 − T/T_lock);
    /// through a free one, on a slippery road, the drive spins both up alike.
    #[test]
    fn the_differential_holds_the_rear_wheels_as_its_kind() {
        let r = Car::spirit_300().rear_tyre.radius;
        let rear = RearWheels {
            loads: [3000.0, 3000.0],
            vt: [30.0, 30.0],
            vl: 0.0,
            inv_denom: [1.0 / 30.0; 2],
            inv_speed: [1.0 / 30.0; 2],
            inv_axle: 1.0 / 30.0,
        };
        let spun = |kind: DiffKind, drive: f64, omega: [f64; 2], friction: f64| {
            let mut car = Car::spirit_300();
            car.differential.kind = kind;
            let v = Vehicle::new(&car);
            let mut s = v.at_rest(0.0, 0.0, 0.0);
            s.vx = 30.0;
            s.omega = [30.0 / r, omega[0], omega[1]];
            v.rear_wheels(&mut s, 0.0, drive, &rear, [friction; 2], 0.004);
            [s.omega[1], s.omega[2]]
        };
        let w = spun(DiffKind::Spool, 500.0, [30.0 / r, 33.0 / r], 1.0);
        assert_eq!(w[0], w[1]);
        let diff = Car::spirit_300().differential;
        let drive = 600.0;
        let w = spun(DiffKind::LimitedSlip, drive, [30.0 / r, 36.0 / r], 1.0);
        let ratio = (w[0] - w[1]).abs() / (w[0].abs() + w[1].abs());
        assert!(
            ratio <= diff.slip_max * (1.0 - drive / diff.lock_torque) + 1e-12,
            "{ratio}"
        );
        // Both wheels on a road of friction 0.05, from rolling.
        let w = spun(DiffKind::Free, 800.0, [30.0 / r, 30.0 / r], 0.05);
        assert!(w[0] > 30.0 / r && (w[0] - w[1]).abs() < 1e-9, "{w:?}");
    }

    /// A wheel sliding at slip angle α slips sideways by sin α, as simuv2's `wheel.cpp` has it
    /// (s_y = sin(atan2(v_l, v_t))): at α = 0.38 rad the tyre's lateral force is the one at
    /// s_y = 0.371, 2 % short of what tan α = 0.4 would give.
    #[test]
    fn a_wheel_slips_sideways_by_the_sine_of_its_slip_angle() {
        let car = Car::spirit_300();
        let v = Vehicle::new(&car);
        let r = car.rear_tyre.radius;
        let (vt, vl, load) = (30.0, -12.0, 3000.0);
        let rear = RearWheels {
            loads: [load; 2],
            vt: [vt; 2],
            vl,
            inv_denom: [1.0 / vt; 2],
            inv_speed: [1.0 / f64::hypot(vt, vl); 2],
            inv_axle: 1.0 / vt,
        };
        let mut s = v.at_rest(0.0, 0.0, 0.0);
        s.vx = vt;
        s.omega = [vt / r; 3];
        let (_, fy) = v.rear_wheels(&mut s, 0.0, 0.0, &rear, [1.0; 2], 0.004);
        let tyre = &v.tyres[1];
        let fmax = tyre.wheel_max_force(load, 1.0);
        let alpha = (-vl / vt).atan();
        let by = |sy: f64| tyre.forces(0.0, sy, fmax).fy;
        assert!((fy[0] - by(alpha.sin())).abs() < 1e-9 * fmax, "{fy:?}");
        assert!((by(alpha.tan()) - by(alpha.sin())).abs() > 1e-3 * fmax);
    }

    /// Between the table's speeds the downforce per v² is the car's within 0.1 %, and a car
    /// without a ride height keeps its constant.
    #[test]
    fn the_downforce_table_follows_the_car() {
        let car = crate::car::tests::on_springs();
        let v = Vehicle::new(&car);
        for speed in [0.3, 7.77, 31.1, 55.55, 89.9, 149.0] {
            let exact = car.downforce(speed).map(|f| f / (speed * speed));
            let table = v.downforce_per_v2(speed);
            for k in 0..2 {
                assert!(
                    (table[k] - exact[k]).abs() < 1e-3 * exact[k],
                    "{speed}: {table:?} vs {exact:?}"
                );
            }
        }
        let plain = Vehicle::new(&Car::spirit_300());
        assert_eq!(
            plain.downforce_per_v2(42.0),
            Car::spirit_300().downforce(1.0)
        );
    }
}
