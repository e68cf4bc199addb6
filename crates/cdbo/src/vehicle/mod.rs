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
//! - Tyres: each wheel's budget F_z·μ·μ_r·λ(F_z) ([`tyre`]) under its own load, μ_r
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
//!   `wheel.cpp` has it, with v₀ = [`SLIP_SPEED_FLOOR`]; the tyre ([`tyre`]) gives
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

use crate::car::{Car, Drive, G};
use crate::track::Frame;
use bounce::{Bounce, Corner};
use powertrain::{EngineMap, Gearbox, ShiftMap};
use tyre::TyreModel;

/// Floor of the speed that normalises slip (m/s): keeps slip finite when standing.
pub const SLIP_SPEED_FLOOR: f64 = 2.0;
/// ABS and traction control start easing at this fraction of the tyre's peak slip as the car
/// file gives it (the driver's setting: a calibrated car's fitted tyre leaves it), and release
/// fully at twice it.
const AID_SLIP_RATIO: f64 = 0.5;

/// The driver's commands, held between driver updates ([`Vehicle::controls`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controls {
    steer: f64,
    throttle: f64,
    brake: f64,
    /// (sin, cos) of the front wheels' steering angles, left and right: the inner wheel's δ,
    /// the outer one's Ackermann angle ([`Vehicle::controls`]), computed once per driver step.
    wheel_angles: [(f64, f64); 2],
}

impl Controls {
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
    /// Each wheel's bounce over rough ground and kinks ([`bounce`]), front left, front right,
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
    /// What moves a front and a rear wheel over rough ground ([`bounce`]); `None` for a
    /// car without a suspension ([`Car::ride`]), which rides rough ground as smooth.
    corners: Option<[Corner; 2]>,
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

    /// The driver's commands for a road-wheel steering angle δ (rad, positive left), a
    /// throttle and a brake pedal in [0, 1], held between driver updates, with the front
    /// wheels' angles: the inner wheel turned by δ, the outer by simuv2's Ackermann angle
    /// (`steer.cpp`), tan δ_o = L·tan|δ|/(L + T·tan|δ|), T = y_f + y_r; the left wheel is the
    /// inner one in a left-hand turn (δ > 0).
    pub fn controls(&self, steer: f64, throttle: f64, brake: f64) -> Controls {
        let (sin_d, cos_d) = steer.sin_cos();
        let tan_d = (sin_d / cos_d).abs();
        let (l, [y_f, y_r]) = (self.car.wheelbase, self.car.axles.half_track);
        let tan_o = l * tan_d / (l + (y_f + y_r) * tan_d);
        let cos_o = 1.0 / (1.0 + tan_o * tan_o).sqrt();
        let outer = ((tan_o * cos_o).copysign(sin_d), cos_o);
        Controls {
            steer,
            throttle,
            brake,
            wheel_angles: if sin_d >= 0.0 {
                [(sin_d, cos_d), outer]
            } else {
                [outer, (sin_d, cos_d)]
            },
        }
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
    /// logged lap is picked up ([`crate::sim::replay`]), with [`Vehicle::under_way`].
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
    /// lap is picked up ([`crate::sim::replay`]).
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
    /// ([`crate::vehicle::aids::abs`]): one command for the four wheels, eased by each axle whose
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
        crate::vehicle::aids::abs::abs_brake(brake, slides, self.aid_threshold)
    }

    /// The launch clutch for the driver's throttle, taken at the driver's rate `dt` after
    /// its last step, after [`Vehicle::shift`]; for a car the TORCS robot drives
    /// ([`Car::torcs_robot`]; else the clutch stays closed), the robot's law
    /// ([`crate::vehicle::aids::launch::launch_clutch`]), which opens the clutch while pulling away in
    /// first gear and closes it over [`crate::vehicle::aids::launch::LAUNCH_TIME`] of throttle.
    pub fn clutch(&self, s: &mut State, throttle: f64, dt: f64) {
        let car = &self.car;
        if !car.torcs_robot {
            return;
        }
        let k = if self.driven[1] > 0.0 { 1 } else { 0 };
        let launch = crate::vehicle::aids::launch::LaunchCar {
            engine_speed: s.engine_speed,
            red_line: car.rev_limiter,
            first_ratio: car.gears[0] * car.final_drive,
            wheel_radius: self.radius[k],
            speed_x: s.vx,
        };
        s.clutch = crate::vehicle::aids::launch::launch_clutch(
            s.gearbox.gear,
            throttle,
            dt,
            &mut s.launch_time,
            &launch,
        );
    }
}

/// The rear wheels' mean spin (rad/s).
#[inline]
pub fn rear_omega(s: &State) -> f64 {
    0.5 * (s.omega[1] + s.omega[2])
}

/// The step of TORCS's simuv2 (s; `RCM_MAX_DT_SIMU`), at which its slipping clutch blends the
/// engine's speed with the wheels'.
const GAME_STEP: f64 = 0.002;

/// Speed step (m/s) of the table of downforce per v².
const DOWNFORCE_SPEED_STEP: f64 = 0.5;
/// Steps of the table: up to 150 m/s.
const DOWNFORCE_SPEEDS: usize = 300;

pub mod aids;
pub mod barrier;
pub mod bounce;
mod ground;
mod hypot;
mod lanes;
pub mod powertrain;
mod step;
pub mod table;
pub mod tyre;

#[cfg(test)]
mod tests;
