/*
 * cdbo: the robot's driving decisions, as pure functions of numbers.
 *
 * Copyright (C) 2026 the cdbo authors.
 *
 * This program is free software; you can redistribute it and/or modify it under the terms of
 * the GNU General Public License as published by the Free Software Foundation; either version
 * 2 of the License, or (at your option) any later version. See COPYING.
 *
 * Everything the robot (cdbo.cpp) decides from numbers it has gathered: the pedal (the policy
 * pi(x), the demonstrator's speed hold, the profile hold), the line it holds, the steering laws
 * (the PI law and the path tracker), the gearbox, the launch clutch and the traction control.
 * No TORCS header is needed: cdbo.cpp reads the game's car and track and calls these, and
 * crates/cdbo/tests/robot_drive.rs compiles this header alone into a harness
 * (tests/harness.cpp) and checks each function against its Rust definition, named on each,
 * on states recorded from laps of cdbo's simulator. Each is written with the Rust's
 * arithmetic, operation for operation, so the two agree bit for bit; compile with
 * -ffp-contract=off (no fused multiply-adds, which Rust never makes).
 *
 * State a controller keeps between driver steps (an integral, the gear) is passed by
 * reference and updated, as the Rust functions take `&mut`.
 *
 * To add a function (a second policy action, another steering law): write it here, add a
 * line to the table in tests/harness.cpp that reads its inputs and prints its outputs, and a
 * case in crates/cdbo/tests/robot_drive.rs that sends it recorded states and compares the
 * answers with the Rust definition.
 */

#ifndef CDBO_DRIVE_HPP
#define CDBO_DRIVE_HPP

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace drive {

/// v held in [lo, hi] (Rust's f64::clamp, for lo <= hi; NaN stays NaN).
inline double clamp(double v, double lo, double hi) { return v < lo ? lo : (v > hi ? hi : v); }

/// One step of a PI controller with anti-windup (drive/mod.rs pi_control): for the error e
/// over dt seconds, u = clamp(kp e + ki I, -limit, limit), the integral I += e dt only while
/// kp e + ki (I + e dt) lies strictly inside +-limit.
inline double pi_control(double kp, double ki, double limit, double &integral, double e, double dt) {
    double raw = kp * e + ki * (integral + e * dt);
    if (std::fabs(raw) < limit) integral += e * dt;
    return clamp(kp * e + ki * integral, -limit, limit);
}

// ---- The pedal ------------------------------------------------------------------------------

/// sqrt(3), as policy/rkhs.rs SQRT_3.
constexpr double kSqrt3 = 1.7320508075688772;

/// w^T phi(x) before clamping (policy/rkhs.rs RkhsPolicy::raw): the sum over the m >= 2
/// weights of w_i (1 + a) e^-a, a = sqrt(3) |x - i h| / l, h = 1 / (m - 1).
inline double rkhs_raw(const double *weights, std::size_t m, double lengthscale, double x) {
    double h = 1.0 / double(m - 1);
    double sum = -0.0;  // the neutral element Rust's f64 sum starts from
    for (std::size_t i = 0; i < m; i++) {
        double a = kSqrt3 * (std::fabs(x - double(i) * h) / lengthscale);
        sum += weights[i] * ((1.0 + a) * std::exp(-a));
    }
    return sum;
}

/// pi(x) of an (x, a) table of n >= 1 points, xa = x1 a1 x2 a2 ... with x increasing: linear
/// in between, held beyond the ends (policy/table.rs PolicyTable::action, interp.rs linear).
inline double table_action(const double *xa, std::size_t n, double x) {
    std::size_t i = 0;  // the number of points at or left of x
    while (i < n && xa[2 * i] <= x) i++;
    if (i == 0) return xa[1];
    if (i >= n) return xa[2 * n - 1];
    double x0 = xa[2 * i - 2], a0 = xa[2 * i - 1], x1 = xa[2 * i], a1 = xa[2 * i + 1];
    return a0 + (a1 - a0) * (x - x0) / (x1 - x0);
}

/// The demonstrator's gains (drive/demo.rs KP, KI).
constexpr double kSpeedHoldKp = 0.5;
constexpr double kSpeedHoldKi = 0.1;

/// The demonstrator holding `target` m/s at `speed` (drive/demo.rs SpeedHold::pedal): the
/// PI control of the speed error with limit 1.
inline double speed_hold(double target, double speed, double dt, double &integral) {
    return pi_control(kSpeedHoldKp, kSpeedHoldKi, 1.0, integral, target - speed, dt);
}

/// The profile hold's gain (per m/s), preview (s) and floor (m/s) (drive/profile.rs, the
/// ceiling's tracker constants ceiling.rs TRACKER_GAIN, PREVIEW_S, TRACKER_FLOOR_MPS).
constexpr double kProfileGain = 1.0;
constexpr double kProfilePreview = 0.3;
constexpr double kProfileFloor = 10.0;

/// v(u) of a profile of n + 1 >= 2 values, linear between them, u in [0, n]
/// (drive/profile.rs ProfileHold::at).
inline double profile_at(const double *profile, std::size_t n, double u) {
    std::size_t j = std::min(std::size_t(std::floor(u)), n - 1);
    return profile[j] + (profile[j + 1] - profile[j]) * (u - double(j));
}

/// The profile hold's target (drive/profile.rs ProfileHold::target): k times the minimum of
/// the profile of n + 1 >= 2 values (linear between them, spaced evenly over a lap of
/// `length` m) over the lap fractions [x, x + speed kProfilePreview / length], each clamped to
/// [0, 1], at least kProfileFloor.
inline double profile_target(const double *profile, std::size_t n, double length, double k,
                             double x, double speed) {
    double nn = double(n);
    double u0 = clamp(x, 0.0, 1.0) * nn;
    double u1 = clamp(x + speed * kProfilePreview / length, 0.0, 1.0) * nn;
    double v = std::fmin(profile_at(profile, n, u0), profile_at(profile, n, u1));
    for (std::size_t i = std::size_t(std::floor(u0)) + 1; double(i) < u1; i++) {
        v = std::fmin(v, profile[i]);
    }
    return std::fmax(k * v, kProfileFloor);
}

/// The profile hold's pedal (drive/profile.rs ProfileHold::pedal):
/// clamp(kProfileGain (target - speed), -1, 1).
inline double profile_hold(const double *profile, std::size_t n, double length, double k, double x,
                           double speed) {
    return clamp(kProfileGain * (profile_target(profile, n, length, k, x, speed) - speed), -1.0, 1.0);
}

/// The pedal command a driver step uses (sim/lap.rs Simulator::lap): the pedal's value held
/// in [-1, 1], NaN taken as 0.
inline double pedal_command(double v) { return std::isnan(v) ? 0.0 : clamp(v, -1.0, 1.0); }

/// The pedal command on a flying lap's run-up (drive/mod.rs run_up_pedal): max(a, clamp(v_min -
/// speed, -1, 1)), v_min the profile tracker's floor.
inline double run_up_pedal(double a, double speed) {
    return std::fmax(a, clamp(kProfileFloor - speed, -1.0, 1.0));
}

// ---- The steering ---------------------------------------------------------------------------

/// The look-ahead distance max(d_min, t_la v) (m) (drive/steering.rs Steering::lookahead).
inline double lookahead(double lookahead_time, double lookahead_min, double speed) {
    return std::fmax(lookahead_time * speed, lookahead_min);
}

/// The angle from the heading (cos yaw, sin yaw) to (dx, dy), in (-pi, pi]
/// (drive/steering.rs bearing).
inline double bearing(double dx, double dy, double sin_yaw, double cos_yaw) {
    return std::atan2(cos_yaw * dy - sin_yaw * dx, cos_yaw * dx + sin_yaw * dy);
}

/// The road-wheel angle (rad) for the bearing e of a target d metres ahead
/// (drive/steering.rs steering_law): PI control with kp = 2 L / d, ki, limit +-steer_lock.
inline double steering_law(double e, double d, double wheelbase, double ki, double steer_lock,
                           double &integral, double dt) {
    return pi_control(2.0 * wheelbase / d, ki, steer_lock, integral, e, dt);
}

// ---- The line -------------------------------------------------------------------------------

/// The periodic function through the n >= 1 values y_j at x_j = j P / n (y_0 again at P) at x
/// wrapped into [0, P) (interp.rs periodic_linear): u = (x mod P) / (P / n),
/// j = min(floor(u), n - 1), t = u - j, y_j (1 - t) + y_((j + 1) mod n) t. The robot's line:
/// the offsets d_j (m, positive left) at stations j L / n of a lap of length L.
inline double periodic_linear(const double *values, std::size_t n, double period, double x) {
    double h = period / double(n);
    double r = std::fmod(x, period);  // Rust's rem_euclid: the remainder made non-negative
    if (r < 0.0) r += std::fabs(period);
    double u = r / h;
    std::size_t j = std::min(std::size_t(std::floor(u)), n - 1);
    double t = u - double(j);
    return values[j] * (1.0 - t) + values[(j + 1) % n] * t;
}

/// The point d metres left of (x, y) on a line heading (cos h, sin h): (x - d sin h,
/// y + d cos h) (track/mod.rs offset_left, the path point c(s) + d(s) n(s)).
inline void offset_left(double x, double y, double sin_h, double cos_h, double d, double *px,
                        double *py) {
    *px = x - d * sin_h;
    *py = y + d * cos_h;
}

// ---- The path tracker ------------------------------------------------------------------------

/// Half the spacing (m) of the path points the heading and curvature are read from
/// (drive/tracker.rs PATH_STEP: one station of a racing line, line::SPACING).
constexpr double kPathStep = 3.0;
/// The speed (m/s) below which the tracker's gains are those of this speed
/// (drive/tracker.rs MIN_SPEED).
constexpr double kTrackerMinSpeed = 1.0;

/// The speed the tracker's gains are taken at, max(v, kTrackerMinSpeed)
/// (drive/tracker.rs tracker_speed).
inline double tracker_speed(double speed) { return std::fmax(speed, kTrackerMinSpeed); }

/// The signed curvature (1/m, positive turning left) of the circle through three points
/// (drive/tracker.rs curvature):
/// 2 ((p1 - p0) x (p2 - p1)) / (|p1 - p0| |p2 - p1| |p2 - p0|).
inline double curvature(double x0, double y0, double x1, double y1, double x2, double y2) {
    double ax = x1 - x0, ay = y1 - y0;
    double bx = x2 - x1, by = y2 - y1;
    double cx = x2 - x0, cy = y2 - y0;
    double norms = std::fmax(std::hypot(ax, ay) * std::hypot(bx, by) * std::hypot(cx, cy),
                             std::numeric_limits<double>::min());
    return 2.0 * (ax * by - ay * bx) / norms;
}

/// The path tracker's gains (drive/tracker.rs PathTracker).
struct TrackerGains {
    double preview_time;      ///< t_p (s)
    double preview_min;       ///< x_min (m)
    double feedforward_time;  ///< t_f (s)
    double yaw_rate_gain;     ///< c_max
    double yaw_rate_speed;    ///< v_y (m/s): c = min(c_max, v / v_y, g* v I_z / (G a C_f T))
    double yaw_step_gain;     ///< g*, the yaw-rate loop's largest one-step gain
};

/// The driver step T (s) the tracker's law acts at (drive/tracker.rs DRIVER_STEP).
constexpr double kDriverStep = 0.02;

/// The car as the tracker's law reads it (drive/tracker.rs TrackerCar).
struct TrackerCar {
    double mass;         ///< m (kg)
    double wheelbase;    ///< L (m)
    double cg_to_front;  ///< a (m)
    double cg_to_rear;   ///< b (m)
    double steer_lock;   ///< delta_max (rad)
    double yaw_inertia;  ///< I_z (kg m^2)
};

/// The car's state against the path (drive/tracker.rs TrackerInput).
struct TrackerInput {
    double lateral_error;  ///< e (m, positive left of the path)
    double heading_error;  ///< psi - theta_P (rad)
    double curvature;      ///< kappa_f, the path's curvature t_f v ahead (1/m)
    double speed;          ///< v (m/s), tracker_speed of the car's speed
    double yaw_rate;       ///< r (rad/s)
    double cornering[2];   ///< C_f, C_r (N/rad) at this speed
};

/// The road-wheel angle (rad) of the path tracker (drive/tracker.rs PathTracker::law):
/// delta = clamp(G (kappa_d + c (kappa_d - r / v)), -delta_max, delta_max), with
/// c = min(c_max, v / v_y, g* v I_z / (G a C_f T)),
/// kappa_d = kappa_f - (2 / x_p^2) (e + x_p (dpsi - dpsi_ss)), x_p = max(t_p v, x_min),
/// dpsi_ss = kappa_f (m a v^2 / (L C_r) - b), G = max(L + K v^2, L / 4) and the understeer
/// gradient K = (m / L) (b / C_f - a / C_r).
inline double tracker_law(const TrackerGains &g, const TrackerCar &car, const TrackerInput &in) {
    double l = car.wheelbase, a = car.cg_to_front, b = car.cg_to_rear, m = car.mass;
    double e = in.lateral_error, heading_error = in.heading_error, kappa = in.curvature;
    double v = in.speed;
    double cf = in.cornering[0], cr = in.cornering[1];
    double understeer = m / l * (b / cf - a / cr);
    double steady_heading_error = kappa * (m * a * v * v / (l * cr) - b);
    double x_p = std::fmax(g.preview_time * v, g.preview_min);
    double kappa_d = kappa - 2.0 / (x_p * x_p) * (e + x_p * (heading_error - steady_heading_error));
    double gain = std::fmax(l + understeer * v * v, 0.25 * l);
    double one_step = g.yaw_step_gain * v * car.yaw_inertia / (gain * a * cf * kDriverStep);
    double c = std::fmin(std::fmin(g.yaw_rate_gain, v / g.yaw_rate_speed), one_step);
    double delta = gain * (kappa_d + c * (kappa_d - in.yaw_rate / v));
    return clamp(delta, -car.steer_lock, car.steer_lock);
}

// ---- The gearbox ----------------------------------------------------------------------------

/// A car's automatic gearbox: its gears and shift points (sim/powertrain.rs ShiftMap).
struct Gearbox {
    const double *ratios;     ///< total ratio engine -> wheel of each forward gear
    std::size_t gears;        ///< the number of forward gears
    const double *upshift;    ///< per gear a row of `levels` up-shift engine speeds (rad/s)
    std::size_t levels;       ///< throttle levels of a row, a = k / (levels - 1)
    double downshift_margin;  ///< hysteresis of the down-shift
    double shift_time;        ///< (s) the drive is cut this long at a shift
};

/// The engine speed (rad/s) at which to leave `gear` at a throttle in [0, 1], linear between
/// the levels; at 0 or less, or 1 and more, full throttle's (ShiftMap::upshift; a row of one
/// level, which cdbo never hands over, is that point at every throttle).
inline double upshift_at(const Gearbox &box, std::size_t gear, double throttle) {
    std::size_t n = box.levels;
    const double *row = box.upshift + gear * n;
    if (throttle <= 0.0 || throttle >= 1.0 || n < 2) return row[n - 1];
    double f = throttle * double(n - 1);
    std::size_t k = std::min(std::size_t(f), n - 2);
    double t = f - double(k);
    return row[k] + (row[k + 1] - row[k]) * t;
}

/// The gear (0-based) for the driven wheels' spin w (rad/s) and the throttle
/// (sim/powertrain.rs Gearbox::update): nothing while `shifting` (s) is left of a shift;
/// else up when w times the gear's ratio reaches its up-shift point, down when w times the
/// lower gear's ratio is below the margin times the lower gear's point; a shift starts
/// `shift_time` of shifting.
inline void gear_update(const Gearbox &box, std::size_t &gear, double &shifting, double w,
                        double throttle) {
    if (shifting > 0.0) return;
    if (gear + 1 < box.gears && w * box.ratios[gear] >= upshift_at(box, gear, throttle)) {
        gear++;
        shifting = box.shift_time;
    } else if (gear > 0 &&
               w * box.ratios[gear - 1] < box.downshift_margin * upshift_at(box, gear - 1, throttle)) {
        gear--;
        shifting = box.shift_time;
    }
}

// ---- The launch clutch ----------------------------------------------------------------------

/// (s) the clutch's closing over throttle time while pulling away (drive/aids/launch.rs).
constexpr double kLaunchTime = 2.0;
/// (m/s) added to the road speed when closing it early (drive/aids/launch.rs).
constexpr double kLaunchSpeed = 5.0;

/// What the launch clutch reads of the car (drive/aids/launch.rs LaunchCar).
struct LaunchCar {
    double engine_speed;  ///< (rad/s)
    double red_line;      ///< (rad/s) the engine's red line
    double first_ratio;   ///< total ratio engine -> wheel of first gear
    double wheel_radius;  ///< (m) of a driven wheel
    double speed_x;       ///< (m/s) forward speed
};

/// The clutch command in [0, 1] (1 = open) while pulling away in first gear
/// (drive/aids/launch.rs launch_clutch): 0 after first gear; in it, `launch_time` counts the time
/// with throttle, and the clutch closes over kLaunchTime of it,
/// ramp = clamp(1 - time / kLaunchTime, 0, 1), sooner once the engine passes half its red
/// line: min(ramp, max(0, 1 - rolling 2 (w - red / 2) / red)), rolling the road speed plus
/// kLaunchSpeed over the first gear's road speed at the red line.
inline double launch_clutch(std::size_t gear, double throttle, double dt, double &launch_time,
                            const LaunchCar &car) {
    if (gear != 0) return 0.0;
    if (throttle > 0.0) launch_time += dt;
    double ramp = clamp(1.0 - launch_time / kLaunchTime, 0.0, 1.0);
    double red = car.red_line;
    double above_half = car.engine_speed - 0.5 * red;
    if (above_half <= 0.0 || red <= 0.0) return ramp;
    double wheel_speed_at_red = std::fabs(car.wheel_radius * red / car.first_ratio);
    double rolling = (kLaunchSpeed + std::fmax(0.0, car.speed_x)) / wheel_speed_at_red;
    return std::fmin(ramp, std::fmax(0.0, 1.0 - rolling * 2.0 * above_half / red));
}

// ---- Traction control ----------------------------------------------------------------------

/// (m/s) the driven wheels' slip speed past which the throttle eases (drive/aids/traction.rs).
constexpr double kTractionSlip = 2.0;
/// (m/s) the slip speed past kTractionSlip that takes the whole throttle away.
constexpr double kTractionRange = 10.0;

/// The throttle after traction control (drive/aids/traction.rs traction_throttle), for the driven
/// wheels' slip speed s = w R - vx: a - min(a, max(0, s - kTractionSlip) / kTractionRange).
inline double traction_throttle(double throttle, double slip_speed) {
    double excess = std::fmax(slip_speed - kTractionSlip, 0.0);
    return throttle - std::fmin(throttle, excess / kTractionRange);
}

// ---- ABS --------------------------------------------------------------------------------------

/// The one brake command after ABS (drive/aids/abs.rs abs_brake): the pedal times
/// clamp(2 - slide / threshold, 0, 1) for each axle (front, rear) whose slide passes a positive
/// threshold.
inline double abs_brake(double brake, const double slide[2], const double threshold[2]) {
    for (int k = 0; k < 2; k++) {
        if (threshold[k] > 0.0 && slide[k] > threshold[k]) {
            brake *= clamp(2.0 - slide[k] / threshold[k], 0.0, 1.0);
        }
    }
    return brake;
}

}  // namespace drive

#endif
