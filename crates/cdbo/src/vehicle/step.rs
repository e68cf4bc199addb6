//! One step of the vehicle model: loads, tyres, wheels and body integrated over dt (the
//! formulas in [`super`]).

use super::bounce;
use super::hypot::hypot_lanes;
use super::lanes::{F64x4, Lane};
use super::tyre::{Forces, TyreModel};
use super::{Controls, GAME_STEP, SLIP_SPEED_FLOOR, State, Vehicle, rear_omega};
use crate::car::{DiffKind, G};
use crate::track::{Bumps, Frame};

impl Vehicle {
    pub(super) fn driven_omega(&self, s: &State) -> f64 {
        self.driven[0] * s.omega[0] + self.driven[1] * rear_omega(s)
    }

    /// Each wheel's tyre at a step, front left, front right, rear left, rear right, the four
    /// side by side in vector registers: its budget F_max = F_z·μ·μ_r·λ(F_z) under its load
    /// on ground of its friction, its slips sₓ = (ωR − v_t)/max(|v_t|, v₀) and
    /// s_y = −v_l/max(|v|, v₀), |v| = √(v_t² + v_l²) (a rear wheel's as −v_l·(1/max(|v|, v₀))),
    /// its tyre's forces there, and 1/max(|v_t|, v₀).
    #[inline(always)]
    fn wheel_tyres(&self, w: &WheelMotion) -> WheelTyres {
        let tyres = [
            &self.tyres[0],
            &self.tyres[0],
            &self.tyres[1],
            &self.tyres[1],
        ];
        let (vt, vl) = (F64x4::new(w.vt), F64x4::new(w.vl));
        let fmax =
            TyreModel::wheel_max_force_lanes(tyres, F64x4::new(w.loads), F64x4::new(w.friction));
        let inv = F64x4::splat(1.0) / vt.abs().at_least(SLIP_SPEED_FLOOR);
        let speed = hypot_lanes(vt, vl).at_least(SLIP_SPEED_FLOOR);
        // The front wheels divide −v_l by the speed, the rear ones multiply it by the
        // speed's reciprocal: q = n/max(|v|, v₀) with n = −v_l or 1, then s_y = q·1 or q·(−v_l).
        let [l, r, rl, rr] = w.vl;
        let sy = F64x4::new([-l, -r, 1.0, 1.0]) / speed * F64x4::new([1.0, 1.0, -rl, -rr]);
        let sx = (F64x4::new(w.spin) - vt) * inv;
        WheelTyres {
            forces: TyreModel::forces_lanes(tyres, sx, sy, fmax),
            fmax: fmax.to_array(),
            inv: inv.to_array(),
        }
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
            Some(w) => [w[0].friction, w[1].friction, w[2].friction, w[3].friction],
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
        // An axle as the robot reads it: its wheels' mean spin against vₓ.
        let inv_axle = 1.0 / s.vx.abs().max(SLIP_SPEED_FLOOR);

        // Drive torque. A car the TORCS robot drives gets the robot's traction control in
        // every gear, on the driven wheels' mean slip speed ωR − vₓ
        // ([`crate::vehicle::aids::traction`]), as the game's car does: with the rear wheels modelled
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
            throttle = crate::vehicle::aids::traction::traction_throttle(throttle, spin_speed);
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

        // The rear wheels' spins as the differential holds them, and its torque split; then
        // every wheel's velocity in its own frame (a front wheel's turned by its steering
        // angle, [`Vehicle::controls`]) and its tyre's forces.
        let rear_drive = self.driven[1] * drive_torque;
        let diff = self.differential(s, rear_drive);
        let angles = c.wheel_angles;
        let turned =
            |(sn, cs): (f64, f64)| (s.vx * cs + front_lat * sn, -s.vx * sn + front_lat * cs);
        let (left, right) = (turned(angles[0]), turned(angles[1]));
        let (front_spin, rear_radius) = (s.omega[0] * self.radius[0], self.radius[1]);
        let tyres = self.wheel_tyres(&WheelMotion {
            loads: [front_loads[0], front_loads[1], rear_loads[0], rear_loads[1]],
            friction,
            vt: [left.0, right.0, vt_rear[0], vt_rear[1]],
            vl: [left.1, right.1, vl_rear, vl_rear],
            spin: [
                front_spin,
                front_spin,
                diff.omega[0] * rear_radius,
                diff.omega[1] * rear_radius,
            ],
        });

        // The front wheels: one spin for both, each steered, loaded and gripping on its own.
        let (front_x, front_y, front_moment) = {
            let tyre = &self.tyres[0];
            let r = self.radius[0];
            let wheels = [0, 1].map(|i| (tyres.forces[i], tyres.fmax[i], tyres.inv[i]));
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
            &diff,
            &RearWheels {
                forces: [tyres.forces[2], tyres.forces[3]],
                fmax: [tyres.fmax[2], tyres.fmax[3]],
                inv_denom: [tyres.inv[2], tyres.inv[3]],
                inv_axle,
            },
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

/// What the step gives each wheel's tyre ([`Vehicle::wheel_tyres`]), front left, front right,
/// rear left, rear right.
pub(super) struct WheelMotion {
    /// Normal loads (N).
    pub(super) loads: [f64; 4],
    /// The ground's friction under each.
    pub(super) friction: [f64; 4],
    /// Velocities along the wheel, v_t (m/s).
    pub(super) vt: [f64; 4],
    /// Velocities across the wheel, v_l (m/s).
    pub(super) vl: [f64; 4],
    /// Spin speeds ωR (m/s).
    pub(super) spin: [f64; 4],
}

/// Each wheel's tyre at a step ([`Vehicle::wheel_tyres`]), front left, front right, rear
/// left, rear right.
pub(super) struct WheelTyres {
    /// Forces at the slips.
    pub(super) forces: [Forces; 4],
    /// Grip budgets F_max (N).
    pub(super) fmax: [f64; 4],
    /// 1 / max(|v_t|, v₀), the longitudinal slip's denominator.
    pub(super) inv: [f64; 4],
}

/// The rear wheels' tyres at a step, left and right.
pub(super) struct RearWheels {
    /// Forces at the spins the differential holds ([`Differential::omega`]).
    pub(super) forces: [Forces; 2],
    /// Grip budgets F_max (N).
    pub(super) fmax: [f64; 2],
    /// 1 / max(|v_t|, v₀) of each wheel.
    pub(super) inv_denom: [f64; 2],
    /// 1 / max(|vₓ|, v₀) of the car.
    pub(super) inv_axle: f64,
}

/// The rear axle's differential at a step ([`Vehicle::differential`]).
pub(super) struct Differential {
    /// The drive torque at the axle (N·m).
    pub(super) drive: f64,
    /// The wheels' spins as the differential holds them (rad/s), left and right.
    pub(super) omega: [f64; 2],
    /// The drive torque's split between them (N·m).
    pub(super) split: [f64; 2],
    /// Whether they turn as one shaft.
    pub(super) rigid: bool,
    /// The spider's half h: 1/2 on a driven free or limited-slip axle, else 0.
    pub(super) spider: f64,
}

impl Vehicle {
    /// The rear wheels' spins and the drive torque `drive` at the axle (N·m) as simuv2's
    /// `differential.cpp` holds them before their tyres act ([`Vehicle::rear_wheels`]):
    /// through a spool (and a limited slip past its locking torque) both at their mean spin;
    /// through a limited slip below it the speed ratio ρ = |ω₀ − ω₁|/(|ω₀| + |ω₁|) held to
    /// ρ_max = ρ_s·(1 − |T|/T_lock), both spins moved (ρ − ρ_max)·(|ω₀| + |ω₁|)/2 towards
    /// each other and the torque split T·(1 ± (ρ − ρ_max))/2; else as they are, T/2 each.
    pub(super) fn differential(&self, s: &State, drive: f64) -> Differential {
        let diff = &self.car.differential;
        let mut omega = [s.omega[1], s.omega[2]];
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
        Differential {
            drive,
            omega,
            split,
            rigid,
            spider,
        }
    }

    /// Steps the rear wheels' spins, held by the differential `diff` ([`Vehicle::differential`]),
    /// under the brake pedal and their tyres' forces `w` at those spins, and returns their
    /// forces (Fₓ and Fᵧ of the left and right wheels, N), as simuv2's `differential.cpp`
    /// drives them:
    ///
    /// - **Spool** (and a limited slip past its locking torque, T > T_lock or
    ///   T < −T_lock,brake): one shaft, 2I·dω/dt = T − Σ R·Fₓ,i − Σ T_b,i, both wheels at
    ///   their mean spin.
    /// - **Limited slip** below it: the speeds held and the torque split by the differential,
    ///   then as free.
    /// - **Free**: each wheel gets T_i plus simuv2's spider torque, I·dω_i/dt = T_i +
    ///   (τ_j − τ_i)/2 − τ_i − T_b,i with τ = R·Fₓ the tyre's reaction (T_i = T/2).
    /// - A rear axle without drive rolls free: I·dω_i/dt = −τ_i − T_b,i.
    ///
    /// Integrated implicitly in the spins (each τ linear in its wheel's ω, a 2×2 system),
    /// stable at the 4 ms step where simuv2 steps explicitly at 2 ms. ABS eases both brakes
    /// on the axle's mean slip (ω̄R − vₓ)/max(|vₓ|, v₀), except on a car the TORCS robot
    /// drives, whose brake the driver has eased already ([`Vehicle::driver_brake`]).
    #[inline(always)]
    pub(super) fn rear_wheels(
        &self,
        s: &mut State,
        brake_pedal: f64,
        diff: &Differential,
        w: &RearWheels,
        dt: f64,
    ) -> ([f64; 2], [f64; 2]) {
        let tyre = &self.tyres[1];
        let r = self.radius[1];
        let inertia = self.wheel_inertia[1];
        let (omega, split, drive) = (diff.omega, diff.split, diff.drive);

        // ABS on the axle's mean slip.
        let mut brake = brake_pedal * self.max_brake[1];
        let threshold = self.aid_threshold[1];
        let slide = -(0.5 * (omega[0] + omega[1]) * r - s.vx) * w.inv_axle;
        if !self.car.torcs_robot && slide > threshold {
            brake *= (2.0 - slide / threshold).clamp(0.0, 1.0);
        }

        // The tyres' reaction torques τ and dτ/dω.
        let forces = w.forces;
        let tau = [r * forces[0].fx, r * forces[1].fx];
        let dtau_of = |i: usize| (forces[i].dfx_dsx * r * r * w.inv_denom[i]).max(0.0);
        let dtau = [dtau_of(0), dtau_of(1)];
        let brake_of = |i: usize| brake * omega[i].signum() * f64::from(omega[i] != 0.0);
        let brake_torque = [brake_of(0), brake_of(1)];
        let step = if diff.rigid {
            let d = dt * (drive - tau[0] - tau[1] - brake_torque[0] - brake_torque[1])
                / (2.0 * inertia + dt * (dtau[0] + dtau[1]));
            [d; 2]
        } else {
            // (I + dt·d_i·(1 + h))·Δ_i − dt·h·d_j·Δ_j = dt·(T_i + h·(τ_j − τ_i) − τ_i − T_b,i),
            // h the spider's half.
            let h = diff.spider;
            let rhs_of = |i: usize, j: usize| {
                dt * (split[i] + h * (tau[j] - tau[i]) - tau[i] - brake_torque[i])
            };
            let rhs = [rhs_of(0, 1), rhs_of(1, 0)];
            let a_of = |i: usize| inertia + dt * dtau[i] * (1.0 + h);
            let a = [a_of(0), a_of(1)];
            let b = [-dt * h * dtau[0], -dt * h * dtau[1]];
            let det = a[0] * a[1] - b[0] * b[1];
            [
                (rhs[0] * a[1] - b[1] * rhs[1]) / det,
                (a[0] * rhs[1] - b[0] * rhs[0]) / det,
            ]
        };
        let mut fx = [0.0; 2];
        let mut fy = [0.0; 2];
        for i in 0..2 {
            let (f, fmax) = (forces[i], w.fmax[i]);
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

/// (x, y) scaled to the length `fmax`. Rarely needed, so kept out of line: the hot path
/// then skips its square root and division instead of computing them speculatively.
#[cold]
#[inline(never)]
fn scale_to_budget(x: f64, y: f64, fmax: f64) -> (f64, f64) {
    let scale = fmax / (x * x + y * y).sqrt();
    (x * scale, y * scale)
}

/// 1 / time constant of the longitudinal load transfer (1/s): the pitch dynamics follow
/// the acceleration with a 50 ms lag.
const PITCH_RATE: f64 = 20.0;
/// 1 / time constant of the lateral load transfer (1/s): simuv2's body rolls against springs
/// and dampers that, for car1-trb1 (κ = 1.17 MN/m a wheel, slow bump and rebound some
/// 0.08 MN·s/m), settle it over c/κ ≈ 70 ms.
const ROLL_RATE: f64 = 14.0;
