/*
 * cdbo: a TORCS robot that drives one lap the way cdbo's simulator does.
 *
 * Copyright (C) 2026 the cdbo authors.
 *
 * This program is free software; you can redistribute it and/or modify it under the terms of
 * the GNU General Public License as published by the Free Software Foundation; either version
 * 2 of the License, or (at your option) any later version. See COPYING.
 *
 * Throttle and brake follow a pedal a in [-1, 1] (a policy pi(x) of the lap fraction x, the
 * demonstrator's PI speed hold, the profile hold of the calibration's fast probe, or a
 * constant); steering is cdbo's look-ahead PI law
 * (crates/cdbo/src/drive/steering.rs) or its path tracker (crates/cdbo/src/drive/tracker.rs),
 * either holding the path P(s) = c(s) + d(s) n(s) of a line d(s) metres left of the centre
 * line c(s) (n the left normal; the centre line itself unless the settings give a line); the gear is chosen by cdbo's automatic gearbox
 * (crates/cdbo/src/sim/powertrain.rs) from shift points it is given; ABS and traction control
 * ease the pedals once a driver step (crates/cdbo/src/drive/aids/abs.rs, traction.rs; cdbo's
 * simulator applies the same ABS at its driver step and the same traction law at every physics
 * step for a car this robot drives); the lap fails by cdbo's rules (sim/lap.rs),
 * judged from the game's car state. On completion or failure it writes one JSON line and ends
 * the game process at once. The decisions themselves (pedal, steering laws, gearbox, launch
 * clutch, traction control, ABS)
 * are the pure functions of drive.hpp, checked against cdbo's Rust by its tests; this file
 * reads the game's state for them and applies their commands.
 *
 * Settings: the file named by the attribute "settings" of section "cdbo" in
 * drivers/cdbo/cdbo.xml, relative to the game's local directory (-l) unless absolute. One
 * "key values..." per line (of any length), '#' starts a comment:
 *   output PATH                  the JSON line goes here (appended)
 *   trace PATH                   optional: every driver step (50 Hz) as CSV
 *   pedal demo V | pedal constant A | pedal rkhs L W1 ... WM | pedal table X1 A1 X2 A2 ...
 *     | pedal profile K L V0 ... VN   the profile hold (drive::profile_hold): k times the
 *                                speeds V0 ... VN (m/s) at N + 1 >= 2 stations spaced evenly
 *                                over a lap of L m (the first on the start line, the last at
 *                                the finish), linear in between
 *   wheelbase L                  (m), the steering gain's L
 *   line L D1 ... DN             optional: the line both steerings hold, offsets (m, positive
 *                                left of the centre line) at the N >= 2 stations (j - 1) L / N
 *                                of a lap of length L (m), linear in between and around the
 *                                lap's end (drive::periodic_linear); without it the centre line
 *   steering pi T_LA D_MIN K_I   the PI law: look-ahead time (s), shortest look-ahead (m),
 *                                integral gain
 *   steering tracker T_P X_MIN T_F C V_Y G1   the path tracker: preview time (s), shortest
 *                                preview (m), feed-forward time (s), yaw-rate gain, the
 *                                speed per unit of it below that gain (m/s) and the yaw-rate
 *                                loop's largest one-step gain
 *   chassis M A B IZ             (the tracker) mass (kg), distances of the front and rear
 *                                axle from the centre of gravity (m), yaw inertia (kg m^2)
 *   cornering_front V1 C1 ...    (the tracker) the axle's cornering stiffness (N/rad) on a
 *   cornering_rear V1 C1 ...     surface of friction 1 at speeds V increasing (m/s), linear
 *                                in between, held beyond the ends; scaled by the friction of
 *                                the car's segment
 *   ratios G1 ... GN             total ratio engine -> wheel of each forward gear
 *   throttle_levels K            throttle levels of the shift map, a = k / (K - 1)
 *   upshift W11 ... W1K ... WNK  engine speed (rad/s) at which to leave each gear, a row of
 *                                K levels per gear (interpolated in the throttle)
 *   downshift_margin F           hysteresis of the down-shift
 *   shift_time S                 (s) no new shift decision during a shift
 *   driven F R                   weights of the front and rear axle's spin in the drive speed
 *   aid_slip F R                 slip at which ABS starts easing, per axle
 *   off_track_margin M           (m) beyond half the width
 *   time_limit S                 (s)
 *   flying F                     1: time the flying lap, the second of two from the standing
 *                                start, line to line (the pedal and line read at the fraction
 *                                of the lap the car is on); 0 (default): the standing lap
 */

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <string>
#include <vector>
#include <unistd.h>

#include <car.h>
#include <raceman.h>
#include <robot.h>
#include <robottools.h>
#include <tgf.h>
#include <track.h>

#include "drive.hpp"

namespace {

using drive::clamp;

const double kSpinSlipTan = 0.5773502691896258;  // 1 / tan 60 deg (sim/lap.rs)
const double kSpinMinSpeed = 3.0;
const double kBackwardsDistance = 10.0;
const double kStallSpeed = 1.0;  // sim/lap.rs STALL_SPEED
const double kStallTime = 5.0;   // sim/lap.rs STALL_TIME
const double kSlipSpeedFloor = 2.0;  // sim/vehicle.rs SLIP_SPEED_FLOOR

struct Settings {
    std::string output = "lap.jsonl";
    std::string trace;
    std::string pedal = "demo";
    std::vector<double> pedal_args = {15.0};
    double wheelbase = 2.6;
    double line_length = 0.0;
    std::vector<double> line;  // the line's offsets; empty: the centre line
    bool tracker = false;  // the path tracker, else the PI law
    double lookahead_time = 0.8, lookahead_min = 12.0, ki = 0.1;
    drive::TrackerGains gains = {0.4, 10.0, 0.15, 4.0, 6.0, 1.6};
    double mass = 0.0, cg_to_front = 0.0, cg_to_rear = 0.0, yaw_inertia = 0.0;
    std::vector<double> cornering[2];  // (v, C) pairs per axle
    std::vector<double> ratios, upshift;
    size_t throttle_levels = 1;
    double downshift_margin = 0.85, shift_time = 0.2;
    double driven[2] = {0.0, 1.0};
    double aid_slip[2] = {0.0, 0.0};
    double off_track_margin = 1.0;
    double time_limit = 0.0;
    bool flying = false;
};

struct Lap {
    Settings cfg;
    std::string error;
    tTrack *track = nullptr;
    FILE *trace = nullptr;
    double start_time = -1.0, last_time = 0.0;
    double distance = 0.0, farthest = 0.0, last_station = 0.0, slow_for = 0.0;
    bool slow_off_road = false;  // off the road since the car became slow
    double lap_start = 0.0;  // the timed lap's start: 0, or one length into a flying lap
    double standing = -1.0;  // a flying lap's standing lap (s), once completed
    double steer_integral = 0.0, demo_integral = 0.0;
    drive::Gearbox gearbox = {};  // points into cfg, set once the settings are read
    size_t gear = 0;              // 0-based, as in cdbo
    double shifting = 0.0;        // time left in a shift (s)
    double launch_time = 0.0;     // time with throttle in first gear (s)
    bool done = false;
};

Lap lap;

std::string resolve(const std::string &path) {
    if (path.empty() || path[0] == '/') return path;
    return std::string(GetLocalDir()) + path;
}

bool read_settings(const std::string &path, Settings *s, std::string *error) {
    FILE *f = fopen(path.c_str(), "r");
    if (!f) {
        *error = "cannot read the settings file " + path;
        return false;
    }
    // getline grows the buffer to the longest line (a line's table is one line per lap metre).
    char *line = nullptr;
    size_t capacity = 0;
    int number = 0;
    auto fail = [&]() {
        free(line);
        fclose(f);
        return false;
    };
    while (getline(&line, &capacity, f) != -1) {
        number++;
        if (char *hash = strchr(line, '#')) *hash = 0;
        char *save = nullptr;
        char *key = strtok_r(line, " \t\r\n", &save);
        if (!key) continue;
        std::vector<double> nums;
        std::string word;
        for (char *tok; (tok = strtok_r(nullptr, " \t\r\n", &save));) {
            char *end = nullptr;
            double v = strtod(tok, &end);
            if (*end == 0 && std::isfinite(v)) {
                nums.push_back(v);
            } else if (word.empty() && nums.empty()) {
                word = tok;
            } else {
                *error = path + ":" + std::to_string(number) + ": " + key + ": '" + tok +
                         "' is not a finite number";
                return fail();
            }
        }
        std::string k = key;
        auto need = [&](size_t n) {
            if (nums.size() < n) {
                *error = path + ":" + std::to_string(number) + ": " + k + " needs " +
                         std::to_string(n) + " number(s)";
                return false;
            }
            return true;
        };
        bool ok = true;
        if (k == "output") s->output = word;
        else if (k == "trace") s->trace = word;
        else if (k == "pedal") { s->pedal = word; s->pedal_args = nums; }
        else if (k == "wheelbase") { if ((ok = need(1))) s->wheelbase = nums[0]; }
        else if (k == "flying") { if ((ok = need(1))) s->flying = nums[0] != 0.0; }
        else if (k == "line") {
            if ((ok = need(3) && nums[0] > 0.0)) { s->line_length = nums[0]; s->line.assign(nums.begin() + 1, nums.end()); }
            else *error = path + ":" + std::to_string(number) + ": line needs a positive length and at least 2 offsets";
        }
        else if (k == "steering" && word == "pi") {
            if ((ok = need(3))) { s->tracker = false; s->lookahead_time = nums[0]; s->lookahead_min = nums[1]; s->ki = nums[2]; }
        }
        else if (k == "steering" && word == "tracker") {
            if ((ok = need(6))) { s->tracker = true; s->gains = {nums[0], nums[1], nums[2], nums[3], nums[4], nums[5]}; }
        }
        else if (k == "steering") {
            *error = path + ":" + std::to_string(number) + ": steering must be 'pi T_LA D_MIN K_I' or "
                     "'tracker T_P X_MIN T_F C V_Y G1', got '" + word + "'";
            ok = false;
        }
        else if (k == "chassis") {
            if ((ok = need(4))) { s->mass = nums[0]; s->cg_to_front = nums[1]; s->cg_to_rear = nums[2]; s->yaw_inertia = nums[3]; }
        }
        else if (k == "cornering_front") s->cornering[0] = nums;
        else if (k == "cornering_rear") s->cornering[1] = nums;
        else if (k == "ratios") s->ratios = nums;
        else if (k == "upshift") s->upshift = nums;
        else if (k == "throttle_levels") {
            if ((ok = need(1) && nums[0] >= 2.0 && nums[0] == std::floor(nums[0]))) s->throttle_levels = size_t(nums[0]);
            else *error = path + ":" + std::to_string(number) + ": throttle_levels needs a whole number >= 2";
        }
        else if (k == "downshift_margin") { if ((ok = need(1))) s->downshift_margin = nums[0]; }
        else if (k == "shift_time") { if ((ok = need(1))) s->shift_time = nums[0]; }
        else if (k == "driven") { if ((ok = need(2))) { s->driven[0] = nums[0]; s->driven[1] = nums[1]; } }
        else if (k == "aid_slip") { if ((ok = need(2))) { s->aid_slip[0] = nums[0]; s->aid_slip[1] = nums[1]; } }
        else if (k == "off_track_margin") { if ((ok = need(1))) s->off_track_margin = nums[0]; }
        else if (k == "time_limit") { if ((ok = need(1))) s->time_limit = nums[0]; }
        else {
            *error = path + ":" + std::to_string(number) + ": unknown setting '" + k + "'";
            ok = false;
        }
        if (!ok) return fail();
    }
    free(line);
    fclose(f);
    if (s->ratios.empty() || s->ratios.size() * s->throttle_levels != s->upshift.size()) {
        *error = path + ": 'upshift' must give 'throttle_levels' numbers per gear of 'ratios'";
        return false;
    }
    if (s->tracker) {
        bool chassis_ok = s->mass > 0.0 && s->cg_to_front > 0.0 && s->cg_to_rear > 0.0 && s->yaw_inertia > 0.0;
        for (const std::vector<double> &c : s->cornering) {
            chassis_ok = chassis_ok && c.size() >= 2 && c.size() % 2 == 0;
            for (size_t i = 2; chassis_ok && i < c.size(); i += 2) chassis_ok = c[i] > c[i - 2];
        }
        if (!chassis_ok) {
            *error = path + ": the path tracker needs 'chassis M A B IZ' (positive) and "
                            "'cornering_front' and 'cornering_rear' tables 'V1 C1 ...' with V increasing";
            return false;
        }
    }
    const std::string &p = s->pedal;
    bool pedal_ok = (p == "demo" && s->pedal_args.size() == 1 && s->pedal_args[0] > 0) ||
                    (p == "constant" && s->pedal_args.size() == 1) ||
                    (p == "rkhs" && s->pedal_args.size() >= 3 && s->pedal_args[0] > 0) ||
                    (p == "table" && s->pedal_args.size() >= 2 && s->pedal_args.size() % 2 == 0) ||
                    (p == "profile" && s->pedal_args.size() >= 4 && s->pedal_args[1] > 0);
    for (size_t i = 2; pedal_ok && p == "table" && i < s->pedal_args.size(); i += 2) {
        pedal_ok = s->pedal_args[i] > s->pedal_args[i - 2];
    }
    if (!pedal_ok) {
        *error = path + ": pedal must be 'demo V', 'constant A', 'rkhs L W1 W2 ...', "
                        "'table X1 A1 ...' with x increasing or 'profile K L V0 V1 ...' with L > 0";
        return false;
    }
    return true;
}

/// The pedal command a in [-1, 1] at lap fraction x.
double pedal(double x, double speed, double dt) {
    const std::vector<double> &a = lap.cfg.pedal_args;
    double v;
    if (lap.cfg.pedal == "demo") {
        v = drive::speed_hold(a[0], speed, dt, lap.demo_integral);
    } else if (lap.cfg.pedal == "constant") {
        v = a[0];
    } else if (lap.cfg.pedal == "profile") {
        v = drive::profile_hold(a.data() + 2, a.size() - 3, a[1], a[0], x, speed);
    } else if (lap.cfg.pedal == "rkhs") {
        v = drive::rkhs_raw(a.data() + 1, a.size() - 1, a[0], x);
    } else {
        v = drive::table_action(a.data(), a.size() / 2, x);
    }
    return drive::pedal_command(v);
}

/// The centre-line point s metres from the start line (wrapped onto the lap), and the centre
/// line's heading there (rad).
void centre_point(double s, double *px, double *py, double *heading) {
    double len = lap.track->length;
    s = std::fmod(s, len);
    if (s < 0) s += len;
    tTrackSeg *seg = lap.track->seg;  // the last segment; its next is the first
    for (int i = 0; i < lap.track->nseg; i++) {
        seg = seg->next;
        if (s < seg->lgfromstart + seg->length || i == lap.track->nseg - 1) break;
    }
    double t = s - seg->lgfromstart;
    double sx = 0.5 * (seg->vertex[TR_SL].x + seg->vertex[TR_SR].x);
    double sy = 0.5 * (seg->vertex[TR_SL].y + seg->vertex[TR_SR].y);
    double h = seg->angle[TR_ZS];
    if (seg->type == TR_STR) {
        *px = sx + t * std::cos(h);
        *py = sy + t * std::sin(h);
        *heading = h;
        return;
    }
    double turn = seg->type == TR_LFT ? 1.0 : -1.0;
    double phi = t / seg->radius * turn;
    *heading = h + phi;
    // Rotate the start point about the arc's centre by phi.
    double dx = sx - seg->center.x, dy = sy - seg->center.y;
    *px = seg->center.x + dx * std::cos(phi) - dy * std::sin(phi);
    *py = seg->center.y + dx * std::sin(phi) + dy * std::cos(phi);
}

/// The line's offset d(s) (m, positive left) at station s: the settings' table, linear
/// (drive::periodic_linear); 0 on the centre line.
double line_offset(double s) {
    const Settings &c = lap.cfg;
    return c.line.empty() ? 0.0 : drive::periodic_linear(c.line.data(), c.line.size(), c.line_length, s);
}

/// The path's point at station s: the centre line's point d(s) metres along its left normal
/// (drive::offset_left); the centre-line point itself where d(s) = 0, as cdbo's
/// Track::point_off.
void path_point(double s, double *px, double *py) {
    double heading;
    centre_point(s, px, py, &heading);
    double d = line_offset(s);
    if (d != 0.0) drive::offset_left(*px, *py, std::sin(heading), std::cos(heading), d, px, py);
}

/// The road-wheel angle (rad) of cdbo's look-ahead PI steering (drive/steering.rs), aimed at
/// the path's point the look-ahead distance ahead of the car's station.
double steer(tCarElt *car, double speed, double dt) {
    double d = drive::lookahead(lap.cfg.lookahead_time, lap.cfg.lookahead_min, speed);
    double tx, ty;
    path_point(car->_distFromStartLine + d, &tx, &ty);
    double e = drive::bearing(tx - car->_pos_X, ty - car->_pos_Y, std::sin(car->_yaw), std::cos(car->_yaw));
    return drive::steering_law(e, d, lap.cfg.wheelbase, lap.cfg.ki, car->_steerLock, lap.steer_integral, dt);
}

/// The road-wheel angle (rad) of cdbo's path tracker (drive/tracker.rs) on the path: its
/// points kPathStep either side of the car's station give its heading, three points around the
/// station t_f v ahead its curvature, the car's offset from the middle less the line's offset
/// d(s) is the lateral error, the cornering stiffness is read from the settings' tables at v
/// and scaled by the friction of the car's segment.
double tracker_steer(tCarElt *car, double speed) {
    const Settings &c = lap.cfg;
    double v = drive::tracker_speed(speed);
    double s = car->_distFromStartLine;
    double bx, by, ax, ay;
    path_point(s - drive::kPathStep, &bx, &by);
    path_point(s + drive::kPathStep, &ax, &ay);
    drive::TrackerInput in;
    // psi - theta_P: minus the bearing of the path's tangent from the car's heading.
    in.heading_error = -drive::bearing(ax - bx, ay - by, std::sin(car->_yaw), std::cos(car->_yaw));
    in.lateral_error = car->_trkPos.toMiddle - line_offset(s);
    double sf = s + c.gains.feedforward_time * v;
    double p[6];
    path_point(sf - drive::kPathStep, &p[0], &p[1]);
    path_point(sf, &p[2], &p[3]);
    path_point(sf + drive::kPathStep, &p[4], &p[5]);
    in.curvature = drive::curvature(p[0], p[1], p[2], p[3], p[4], p[5]);
    in.speed = v;
    in.yaw_rate = car->_yaw_rate;
    double friction = car->_trkPos.seg->surface->kFriction;
    for (int k = 0; k < 2; k++) {
        in.cornering[k] = friction * drive::table_action(c.cornering[k].data(), c.cornering[k].size() / 2, v);
    }
    drive::TrackerCar tc = {c.mass, c.wheelbase, c.cg_to_front, c.cg_to_rear, car->_steerLock, c.yaw_inertia};
    return drive::tracker_law(c.gains, tc, in);
}

/// Spin of an axle (rad/s): the mean of its two wheels (0, 1 front; 2, 3 rear).
double axle_omega(tCarElt *car, int axle) {
    return 0.5 * (car->_wheelSpinVel(2 * axle) + car->_wheelSpinVel(2 * axle + 1));
}

/// cdbo's automatic gearbox on the driven wheels' spin, the time left in a shift counted down
/// by the driver step first (cdbo's simulator counts it down every physics step).
void choose_gear(tCarElt *car, double throttle, double dt) {
    lap.shifting = std::fmax(lap.shifting - dt, 0.0);
    double w = lap.cfg.driven[0] * axle_omega(car, 0) + lap.cfg.driven[1] * axle_omega(car, 1);
    drive::gear_update(lap.gearbox, lap.gear, lap.shifting, w, throttle);
}

/// The clutch while pulling away in first gear. cdbo's powertrain lets the clutch slip below
/// idle with the engine giving its idle torque; the game's engine gives no torque below idle
/// and drives the wheels only while it turns faster, so a standing car with the clutch closed
/// barely creeps. As the game's own robots do, the clutch starts open and closes over
/// drive::kLaunchTime of throttle, sooner once the engine passes half its red line with the
/// car rolling; after first gear it stays closed.
double launch_clutch(tCarElt *car, double throttle, double dt) {
    drive::LaunchCar c = {car->_enginerpm, car->_enginerpmRedLine, lap.cfg.ratios[0],
                          car->_wheelRadius(2), car->_speed_x};
    return drive::launch_clutch(lap.gear, throttle, dt, lap.launch_time, c);
}

/// Slip speed of an axle, omega R - v (m/s).
double axle_slip_speed(tCarElt *car, int axle) {
    double r = 0.5 * (car->_wheelRadius(2 * axle) + car->_wheelRadius(2 * axle + 1));
    return axle_omega(car, axle) * r - car->_speed_x;
}

/// Longitudinal slip of an axle, (omega R - v) / max(|v|, v0).
double axle_slip(tCarElt *car, int axle) {
    return axle_slip_speed(car, axle) / std::fmax(std::fabs(car->_speed_x), kSlipSpeedFloor);
}

void json_string(FILE *f, const std::string &s) {
    fputc('"', f);
    for (char ch : s) {
        if (ch == '"' || ch == '\\') fputc('\\', f);
        if ((unsigned char)ch < 0x20) fprintf(f, "\\u%04x", ch);
        else fputc(ch, f);
    }
    fputc('"', f);
}

/// Writes the lap's JSON line and ends the game process: nothing else is left to drive.
[[noreturn]] void finish(double t, double game_time, const char *reason, double lap_time) {
    std::string out = resolve(lap.cfg.output);
    FILE *f = fopen(out.c_str(), "a");
    if (!f) f = stdout;
    double len = lap.track ? lap.track->length : 0.0;
    fprintf(f, "{\"robot\":\"cdbo\",\"track\":");
    json_string(f, lap.track ? lap.track->internalname : "");
    fprintf(f, ",\"length_m\":%.4f", len);
    if (!lap.error.empty()) {
        fprintf(f, ",\"completed\":false,\"error\":");
        json_string(f, lap.error);
    } else if (reason) {
        double d = std::fmax(lap.distance - lap.lap_start, 0.0);
        fprintf(f,
                ",\"completed\":false,\"lap_time_s\":null,\"reward_mps\":0,\"failure\":{\"reason\":\"%s\","
                "\"x\":%.6f,\"distance_m\":%.3f,\"time_s\":%.4f}",
                reason, clamp(d / len, 0.0, 1.0), d, t);
    } else {
        fprintf(f, ",\"completed\":true,\"lap_time_s\":%.4f,\"reward_mps\":%.6f,\"failure\":null",
                lap_time, len / lap_time);
    }
    if (lap.standing >= 0.0) fprintf(f, ",\"standing_lap_s\":%.4f", lap.standing);
    fprintf(f, ",\"simulated_s\":%.4f,\"game_time_s\":%.4f}\n", t, game_time);
    fflush(f);
    if (lap.trace) fflush(lap.trace);
    _exit(0);
}

void new_track(int, tTrack *track, void *, void **settings, tSituation *) {
    lap.track = track;
    *settings = nullptr;
    // The local directory's copy first (one per lap), then the game's data directory.
    void *h = GfParmReadFile(resolve("drivers/cdbo/cdbo.xml").c_str(), GFPARM_RMODE_STD);
    if (!h) h = GfParmReadFile("drivers/cdbo/cdbo.xml", GFPARM_RMODE_STD);
    std::string path = "cdbo-lap.txt";
    if (h) {
        path = GfParmGetStr(h, "cdbo", "settings", path.c_str());
    }
    std::string resolved = resolve(path);
    if (read_settings(resolved, &lap.cfg, &lap.error) && !lap.cfg.trace.empty()) {
        lap.trace = fopen(resolve(lap.cfg.trace).c_str(), "w");
        if (!lap.trace) {
            lap.error = "cannot write the trace " + resolve(lap.cfg.trace);
        } else {
            fprintf(lap.trace,
                    "t_s,distance_m,x,speed_mps,pedal,steer_rad,lateral_m,heading_error_rad,"
                    "slip_angle_rad,gear,rpm,pos_x_m,pos_y_m,yaw_rate_rad_s,wheel_speed_front_mps,"
                    "wheel_speed_rear_left_mps,wheel_speed_rear_right_mps\n");
        }
    }
    if (h) GfParmReleaseHandle(h);
    const Settings &c = lap.cfg;
    lap.gearbox = {c.ratios.data(), c.ratios.size(), c.upshift.data(), c.throttle_levels,
                   c.downshift_margin, c.shift_time};
    if (lap.cfg.time_limit <= 0.0) lap.cfg.time_limit = 30.0 + track->length / 4.0;
}

// Where the car stands on the grid, as a distance along the lap: a grid behind the start line
// (a station short of the length, as on corkscrew) is a negative distance, so that the lap is
// the grid's distance to the line plus one length, and never read as driving backwards.
void place_on_grid(tCarElt *car) {
    lap.last_station = car->_distFromStartLine;
    if (lap.last_station > 0.5 * lap.track->length) lap.last_station -= lap.track->length;
    lap.distance = lap.last_station;
    lap.farthest = lap.distance;
}

void new_race(int, tCarElt *car, tSituation *) { place_on_grid(car); }

void drive(int, tCarElt *car, tSituation *s) {
    memset((void *)&car->ctrl, 0, sizeof(tCarCtrl));
    double now = s->currentTime;
    if (!lap.error.empty()) finish(0.0, now, nullptr, 0.0);
    if (now < 0.0 || lap.start_time < 0.0) {
        // Before the first step of the race the car's station may not be set yet at new_race:
        // place it again where the game has put it.
        place_on_grid(car);
    }
    if (now < 0.0) {
        // The count-down before the start: stand on the brake, as the car does at t < 0 in cdbo.
        car->_brakeCmd = 1.0;
        car->_gearCmd = 1;
        return;
    }
    if (lap.start_time < 0.0) {
        lap.start_time = 0.0;  // the race's start
        lap.last_time = 0.0;
    }
    double t = now - lap.start_time;
    double dt = now - lap.last_time;
    lap.last_time = now;
    double len = lap.track->length;

    // Progress along the centre line, unwrapped across the start line.
    double station = car->_distFromStartLine;
    double ds = station - std::fmod(lap.last_station + len, len);
    if (ds > 0.5 * len) ds -= len;
    if (ds < -0.5 * len) ds += len;
    double before = lap.distance;
    lap.distance += ds;
    lap.last_station = station;
    if (lap.distance >= lap.lap_start + len && ds > 0.0) {
        // Crossed the line between the last driver step and this one: interpolate the time.
        double crossed = t - dt + dt * (lap.lap_start + len - before) / ds;
        if (lap.cfg.flying && lap.standing < 0.0) {
            lap.standing = crossed;
            lap.lap_start = len;
        } else {
            finish(t, now, nullptr, crossed - std::fmax(lap.standing, 0.0));
        }
    }
    lap.farthest = std::fmax(lap.farthest, lap.distance);

    double vx = car->_speed_x, vy = car->_speed_y;
    double speed = std::sqrt(vx * vx + vy * vy);
    tTrackSeg *seg = car->_trkPos.seg;
    double half_width = 0.5 * seg->width;
    double lateral = car->_trkPos.toMiddle;
    double heading_error = car->_yaw - RtTrackSideTgAngleL(&car->_trkPos);
    heading_error = std::atan2(std::sin(heading_error), std::cos(heading_error));
    const char *failure = nullptr;
    if (std::fabs(lateral) > half_width + lap.cfg.off_track_margin) {
        failure = "off_track";
    } else if (car->priv.collision & SEM_COLLISION_XYSCENE) {
        // simuv2 flags a corner of the body driven into a barrier (collide.cpp); only the
        // sound module clears the flag, and a headless race has none.
        failure = "hit_wall";
    } else if (std::cos(heading_error) < 0.0 ||
               (vx < std::fabs(vy) * kSpinSlipTan && speed > kSpinMinSpeed)) {
        failure = "spun";
    } else if (lap.distance < lap.farthest - kBackwardsDistance) {
        failure = "backwards";
    } else if (t > lap.cfg.time_limit) {
        failure = "time_limit";
    } else {
        bool slow = std::fabs(vx) < kStallSpeed && speed < kStallSpeed;
        lap.slow_for = slow ? lap.slow_for + dt : 0.0;
        // A car come to rest off the road (in the gravel short of the margin) left it.
        lap.slow_off_road = slow && (lap.slow_off_road || std::fabs(lateral) > half_width);
        if (lap.slow_for > kStallTime) failure = lap.slow_off_road ? "off_track" : "stalled";
    }
    if (failure) finish(t, now, failure, 0.0);

    double x = clamp((lap.distance - lap.lap_start) / len, 0.0, 1.0);
    double a = pedal(x, speed, dt);
    if (lap.cfg.flying && lap.standing < 0.0) a = drive::run_up_pedal(a, speed);
    double delta = lap.cfg.tracker ? tracker_steer(car, speed) : steer(car, speed, dt);
    choose_gear(car, std::fmax(a, 0.0), dt);

    // Traction control on the driven axle's slip speed and ABS on the one brake command, at
    // the driver's steps (drive/aids/traction.rs, drive/aids/abs.rs).
    int k = lap.cfg.driven[1] > 0.0 ? 1 : 0;
    double throttle = drive::traction_throttle(std::fmax(a, 0.0), axle_slip_speed(car, k));
    double slide[2] = {-axle_slip(car, 0), -axle_slip(car, 1)};
    double brake = drive::abs_brake(std::fmax(-a, 0.0), slide, lap.cfg.aid_slip);

    car->_steerCmd = delta / car->_steerLock;
    car->_accelCmd = throttle;
    car->_brakeCmd = brake;
    car->_gearCmd = int(lap.gear) + 1;
    car->_clutchCmd = launch_clutch(car, throttle, dt);

    if (lap.trace) {
        // The wheels' speeds ω·R: the front axle's mean, the rear left's, the rear right's
        // (TORCS's wheels: 0 front right, 1 front left, 2 rear right, 3 rear left).
        auto wheel = [car](int i) { return car->_wheelSpinVel(i) * car->_wheelRadius(i); };
        fprintf(lap.trace,
                "%.3f,%.3f,%.6f,%.4f,%.4f,%.5f,%.4f,%.5f,%.5f,%d,%.0f,%.3f,%.3f,%.5f,%.4f,%.4f,%.4f\n", t,
                lap.distance, x, speed, a, delta, lateral, heading_error,
                std::atan2(vy, std::fmax(std::fabs(vx), 1e-9)), car->_gear, car->_enginerpm * 30.0 / M_PI,
                car->_pos_X, car->_pos_Y, car->_yaw_rate, 0.5 * (wheel(0) + wheel(1)), wheel(3), wheel(2));
    }
}

void end_race(int, tCarElt *, tSituation *) {}

void shutdown(int) {
    if (lap.trace) fclose(lap.trace);
    lap.trace = nullptr;
}

int init_robot(int, void *pt) {
    tRobotItf *itf = (tRobotItf *)pt;
    itf->rbNewTrack = new_track;
    itf->rbNewRace = new_race;
    itf->rbDrive = drive;
    itf->rbPitCmd = nullptr;
    itf->rbEndRace = end_race;
    itf->rbShutdown = shutdown;
    itf->index = 0;
    return 0;
}

}  // namespace

extern "C" int cdbo(tModInfo *info) {
    memset(info, 0, 10 * sizeof(tModInfo));
    info->name = strdup("cdbo");
    info->desc = strdup("cdbo: one lap as cdbo's simulator drives it");
    info->fctInit = init_robot;
    info->gfId = ROB_IDENT;
    info->index = 0;
    return 0;
}
