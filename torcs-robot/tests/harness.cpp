/*
 * The test harness of drive.hpp: crates/cdbo/tests/robot_drive.rs compiles it beside the
 * header (no TORCS needed) and checks the answers against cdbo's Rust.
 *
 * Copyright (C) 2026 the cdbo authors. GPL-2-or-later, as the robot (see ../COPYING).
 *
 * Reads lines "NAME V1 V2 ..." from standard input and answers each with one line of the
 * function's outputs, %.17g (which reads back exactly); a list of numbers is given as its
 * length, then its numbers; state the function updates (an integral, the gear) is given
 * before the inputs and printed after the outputs. An unknown name or a short line is
 * answered "error ..." and ends the harness with status 1.
 */

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "drive.hpp"

namespace {

/// The numbers of one input line, read in order.
struct Args {
    std::vector<double> v;
    std::size_t next = 0;
    bool short_line = false;

    double num() {
        if (next < v.size()) return v[next++];
        short_line = true;
        return 0.0;
    }
    std::size_t count() { return std::size_t(num()); }
    /// A list of n numbers (at least one element's room, so that a short line stays safe).
    std::vector<double> list(std::size_t n) {
        std::vector<double> out(n ? n : 1);
        for (std::size_t i = 0; i < n; i++) out[i] = num();
        return out;
    }
};

using Case = std::function<std::vector<double>(Args &)>;

/// The line's table periodic_linear reads (set by line_table; a table is long, the calls many).
std::vector<double> line_values;
double line_period = 0.0;
/// The speed profile profile_hold reads (set by profile_table).
std::vector<double> profile_values;

/// Each function of drive.hpp: its inputs as read, its outputs (then updated state) as printed.
const std::map<std::string, Case> kCases = {
    {"rkhs",  // L M W1..WM X -> w^T phi(x)
     [](Args &a) {
         double l = a.num();
         std::size_t m = a.count();
         std::vector<double> w = a.list(m);
         return std::vector<double>{drive::rkhs_raw(w.data(), m, l, a.num())};
     }},
    {"table",  // N X1 A1 .. XN AN X -> pi(x)
     [](Args &a) {
         std::size_t n = a.count();
         std::vector<double> xa = a.list(2 * n);
         return std::vector<double>{drive::table_action(xa.data(), n, a.num())};
     }},
    {"profile_constants",  // -> kProfileGain kProfilePreview kProfileFloor
     [](Args &) {
         return std::vector<double>{drive::kProfileGain, drive::kProfilePreview,
                                    drive::kProfileFloor};
     }},
    {"profile_table",  // N V0..VN -> N: the profile profile_hold reads from now on
     [](Args &a) {
         std::size_t n = a.count();
         std::vector<double> v = a.list(n + 1);
         if (a.short_line || n < 1) return std::vector<double>{};
         profile_values = v;
         return std::vector<double>{double(n)};
     }},
    {"profile_hold",  // K L X SPEED -> target a, of the last profile_table
     [](Args &a) {
         double k = a.num(), length = a.num(), x = a.num(), speed = a.num();
         if (profile_values.size() < 2) return std::vector<double>{};
         const double *v = profile_values.data();
         std::size_t n = profile_values.size() - 1;
         return std::vector<double>{drive::profile_target(v, n, length, k, x, speed),
                                    drive::profile_hold(v, n, length, k, x, speed)};
     }},
    {"pedal_command",  // V -> a
     [](Args &a) { return std::vector<double>{drive::pedal_command(a.num())}; }},
    {"run_up_pedal",  // A SPEED -> a
     [](Args &a) {
         double pedal = a.num(), speed = a.num();
         return std::vector<double>{drive::run_up_pedal(pedal, speed)};
     }},
    {"speed_hold",  // INTEGRAL TARGET SPEED DT -> a INTEGRAL'
     [](Args &a) {
         double integral = a.num(), target = a.num(), speed = a.num(), dt = a.num();
         double out = drive::speed_hold(target, speed, dt, integral);
         return std::vector<double>{out, integral};
     }},
    {"lookahead",  // T_LA D_MIN SPEED -> d
     [](Args &a) {
         double t = a.num(), d_min = a.num();
         return std::vector<double>{drive::lookahead(t, d_min, a.num())};
     }},
    {"bearing",  // DX DY SIN COS -> e
     [](Args &a) {
         double dx = a.num(), dy = a.num(), s = a.num();
         return std::vector<double>{drive::bearing(dx, dy, s, a.num())};
     }},
    {"steering_law",  // INTEGRAL E D L KI LOCK DT -> delta INTEGRAL'
     [](Args &a) {
         double integral = a.num(), e = a.num(), d = a.num(), l = a.num(), ki = a.num(),
                lock = a.num(), dt = a.num();
         double out = drive::steering_law(e, d, l, ki, lock, integral, dt);
         return std::vector<double>{out, integral};
     }},
    {"line_table",  // N Y1..YN PERIOD -> N: the table periodic_linear reads from now on
     [](Args &a) {
         std::size_t n = a.count();
         std::vector<double> y = a.list(n);
         double period = a.num();
         if (a.short_line || n == 0) return std::vector<double>{};
         line_values = y;
         line_period = period;
         return std::vector<double>{double(n)};
     }},
    {"periodic_linear",  // X -> y of the last line_table
     [](Args &a) {
         double x = a.num();
         if (line_values.empty()) return std::vector<double>{};
         return std::vector<double>{
             drive::periodic_linear(line_values.data(), line_values.size(), line_period, x)};
     }},
    {"offset_left",  // X Y SIN COS D -> PX PY
     [](Args &a) {
         double x = a.num(), y = a.num(), s = a.num(), c = a.num(), d = a.num(), px, py;
         drive::offset_left(x, y, s, c, d, &px, &py);
         return std::vector<double>{px, py};
     }},
    {"tracker_constants",  // -> kPathStep kTrackerMinSpeed kDriverStep
     [](Args &) { return std::vector<double>{drive::kPathStep, drive::kTrackerMinSpeed, drive::kDriverStep}; }},
    {"tracker_speed",  // SPEED -> v
     [](Args &a) { return std::vector<double>{drive::tracker_speed(a.num())}; }},
    {"curvature",  // X0 Y0 X1 Y1 X2 Y2 -> kappa
     [](Args &a) {
         double x0 = a.num(), y0 = a.num(), x1 = a.num(), y1 = a.num(), x2 = a.num();
         return std::vector<double>{drive::curvature(x0, y0, x1, y1, x2, a.num())};
     }},
    {"tracker_law",  // T_P X_MIN T_F C V_Y G1  M L A B LOCK IZ  E DPSI KAPPA V R CF CR -> delta
     [](Args &a) {
         drive::TrackerGains g;
         g.preview_time = a.num();
         g.preview_min = a.num();
         g.feedforward_time = a.num();
         g.yaw_rate_gain = a.num();
         g.yaw_rate_speed = a.num();
         g.yaw_step_gain = a.num();
         drive::TrackerCar car;
         car.mass = a.num();
         car.wheelbase = a.num();
         car.cg_to_front = a.num();
         car.cg_to_rear = a.num();
         car.steer_lock = a.num();
         car.yaw_inertia = a.num();
         drive::TrackerInput in;
         in.lateral_error = a.num();
         in.heading_error = a.num();
         in.curvature = a.num();
         in.speed = a.num();
         in.yaw_rate = a.num();
         in.cornering[0] = a.num();
         in.cornering[1] = a.num();
         return std::vector<double>{drive::tracker_law(g, car, in)};
     }},
    {"gear_update",  // GEAR SHIFTING N R1..RN K U11..UNK MARGIN SHIFT_TIME W THROTTLE
                     //   -> GEAR' SHIFTING' upshift_at(gear, throttle)
     [](Args &a) {
         std::size_t gear = a.count();
         double shifting = a.num();
         std::size_t n = a.count();
         std::vector<double> ratios = a.list(n);
         std::size_t k = a.count();
         std::vector<double> up = a.list(n * k);
         double margin = a.num(), shift_time = a.num(), w = a.num(), throttle = a.num();
         drive::Gearbox box = {ratios.data(), n, up.data(), k, margin, shift_time};
         if (a.short_line || gear >= n) return std::vector<double>{};
         double point = drive::upshift_at(box, gear, throttle);
         drive::gear_update(box, gear, shifting, w, throttle);
         return std::vector<double>{double(gear), shifting, point};
     }},
    {"launch_clutch",  // LAUNCH_TIME GEAR THROTTLE DT W RED RATIO1 RADIUS VX -> c LAUNCH_TIME'
     [](Args &a) {
         double launch_time = a.num();
         std::size_t gear = a.count();
         double throttle = a.num(), dt = a.num();
         drive::LaunchCar car;
         car.engine_speed = a.num();
         car.red_line = a.num();
         car.first_ratio = a.num();
         car.wheel_radius = a.num();
         car.speed_x = a.num();
         double c = drive::launch_clutch(gear, throttle, dt, launch_time, car);
         return std::vector<double>{c, launch_time};
     }},
    {"traction_throttle",  // THROTTLE SLIP_SPEED -> a
     [](Args &a) {
         double throttle = a.num();
         return std::vector<double>{drive::traction_throttle(throttle, a.num())};
     }},
    {"abs_brake",  // BRAKE SLIDE_F SLIDE_R THRESHOLD_F THRESHOLD_R -> b
     [](Args &a) {
         double brake = a.num();
         double slide[2], threshold[2];
         for (double &s : slide) s = a.num();
         for (double &t : threshold) t = a.num();
         return std::vector<double>{drive::abs_brake(brake, slide, threshold)};
     }},
};

}  // namespace

int main() {
    // One call a line, read whole (a call's numbers run to thousands: a table, a policy);
    // each number parsed where it stands.
    std::string line;
    for (int ch; (ch = getchar_unlocked()) != EOF;) {
        if (ch != '\n') {
            line.push_back(char(ch));
            continue;
        }
        const char *p = line.c_str();
        while (*p == ' ') p++;
        const char *end_of_name = std::strchr(p, ' ');
        if (end_of_name == nullptr) end_of_name = p + std::strlen(p);
        std::string name(p, end_of_name);
        Args args;
        for (p = end_of_name; *p != '\0';) {
            if (*p == ' ') {
                p++;
                continue;
            }
            char *end = nullptr;
            args.v.push_back(std::strtod(p, &end));
            if (end != p) {
                p = end;
                continue;
            }
            // Not a number: read as 0, as strtod gives it, and the word skipped.
            while (*p != '\0' && *p != ' ') p++;
        }
        line.clear();
        auto found = kCases.find(name);
        std::vector<double> out;
        if (found != kCases.end()) out = found->second(args);
        if (found == kCases.end() || args.short_line || args.next != args.v.size() || out.empty()) {
            std::printf("error: '%s' with %zu numbers\n", name.c_str(), args.v.size());
            return 1;
        }
        for (std::size_t i = 0; i < out.size(); i++) std::printf(i ? " %.17g" : "%.17g", out[i]);
        std::printf("\n");
    }
    return 0;
}
