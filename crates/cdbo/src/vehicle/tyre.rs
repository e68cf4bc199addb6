//! The TORCS tyre: a Magic-Formula shape with load sensitivity and combined slip.
//!
//! For a slip vector (sₓ, s_y) with magnitude s = √(sₓ² + s_y²), the force magnitude is
//!
//! F = F_z · μ · μ_surface · λ(F_z) · sin(C·atan(B·s·(1 − E) + E·atan(B·s)))
//!
//! with C = 2 − (2/π)·asin(dynamic friction), B = stiffness / C, E = elasticity factor, and the
//! load sensitivity λ(F_z) = λ_min + (λ_max − λ_min)·exp(k·F_z / F_op), k = ln((1 − λ_min) /
//! (λ_max − λ_min)), which is 1 at the operating load F_op and rises to λ_max at zero load.
//! Longitudinal and lateral forces share this one budget along the slip vector:
//! Fₓ = F·sₓ/s, F_y = F·s_y/s (the friction ellipse of combined slip).
//!
//! The vehicle ([`super`]) gives each wheel its own budget F_z·μ·μ_surface·λ(F_z)
//! under its own load, as TORCS applies it per wheel; the limit solver and the cornering
//! stiffness lump an axle's two tyres at equal loads, F_z·μ·μ_surface·λ(F_z/2).
//!
//! In the hot loop the shape is read as g(u) = f(√u)/√u on u = s² = sₓ² + s_y²: f is odd, so
//! g is smooth in u, and Fₓ = F_max·g(u)·sₓ, F_y = F_max·g(u)·s_y need neither a square root
//! nor a division.

use super::lanes::{AnyLane, F64x4, Lane};
use super::table::HermiteTable;
use crate::car::Tyre;

/// λ_min of the load sensitivity (TORCS default).
pub const LOAD_FACTOR_MIN: f64 = 0.8;
/// λ_max of the load sensitivity (TORCS default).
pub const LOAD_FACTOR_MAX: f64 = 1.6;
/// The slip beyond which simuv2's skid factor grows no more (`wheel.cpp`: min(s, 1.5)).
pub const SKID_SLIP_CAP: f64 = 1.5;

/// Pre-computed Magic-Formula constants of one tyre.
#[derive(Debug, Clone, PartialEq)]
pub struct TyreModel {
    /// Peak friction μ.
    pub mu: f64,
    /// Shape factor C.
    pub c: f64,
    /// Stiffness factor B.
    pub b: f64,
    /// Curvature factor E.
    pub e: f64,
    /// Operating load F_op (N).
    pub operating_load: f64,
    /// k of the load sensitivity.
    load_k: f64,
    /// 1 / F_op.
    inv_operating_load: f64,
    /// Slip magnitude at which the Magic-Formula shape peaks (the skid factor left out).
    pub peak_slip: f64,
    /// The skid factor k ([`Tyre::skid`]): the force is f(s)·(1 + k·min(s, [`SKID_SLIP_CAP`])).
    pub skid: f64,
    /// The largest force per unit budget: 1 without a skid factor, else the largest
    /// f(s)·(1 + k·min(s, [`SKID_SLIP_CAP`])).
    pub force_cap: f64,
    /// g(u) = f(√u)/√u and g′(u), tabulated on u = s² ∈ [0, 1].
    ratio_table: HermiteTable,
    /// λ and dλ/dz of the load sensitivity, tabulated on z = F_z/F_op ∈ [0, 8].
    load_table: HermiteTable,
}

impl TyreModel {
    /// The model of a car's tyre.
    pub fn new(t: &Tyre) -> TyreModel {
        let c = 2.0 - t.dynamic_friction.clamp(0.0, 1.0).asin() * 2.0 / std::f64::consts::PI;
        let b = t.stiffness / c;
        let load_k = ((1.0 - LOAD_FACTOR_MIN) / (LOAD_FACTOR_MAX - LOAD_FACTOR_MIN)).ln();
        let mut m = TyreModel {
            mu: t.mu,
            c,
            b,
            e: t.elasticity,
            operating_load: t.operating_load,
            load_k,
            inv_operating_load: 1.0 / t.operating_load,
            peak_slip: 0.0,
            skid: t.skid,
            force_cap: 1.0,
            ratio_table: HermiteTable::new(1.0, 0, |_| (0.0, 0.0)),
            load_table: HermiteTable::new(1.0, 0, |_| (0.0, 0.0)),
        };
        m.peak_slip = m.find_peak_slip();
        if m.skid > 0.0 {
            m.force_cap = (0..=3000)
                .map(|i| {
                    let s = i as f64 * 1e-3;
                    m.shape_exact(s).0 * m.skid_multiplier(s * s).0
                })
                .fold(1.0, f64::max);
        }
        // Steps 1/16384 and 1/256 keep the interpolation error of the force below 1e-10 of
        // the budget, and of λ below 1e-11.
        m.ratio_table = HermiteTable::new(1.0 / 16384.0, 16384, |u| m.ratio_exact(u));
        m.load_table = HermiteTable::new(1.0 / 256.0, 2048, |z| {
            let e = (LOAD_FACTOR_MAX - LOAD_FACTOR_MIN) * (load_k * z).exp();
            (LOAD_FACTOR_MIN + e, load_k * e)
        });
        m
    }

    /// Load sensitivity λ(F_z) (tabulated; the formula beyond 8 × the operating load).
    #[inline(always)]
    pub fn load_factor(&self, fz: f64) -> f64 {
        let z = fz * self.inv_operating_load;
        match self.load_table.eval(z) {
            Some((l, _)) => l,
            None => LOAD_FACTOR_MIN + (LOAD_FACTOR_MAX - LOAD_FACTOR_MIN) * (self.load_k * z).exp(),
        }
    }

    /// Largest force one tyre can give under its load `fz` on a surface of friction `surface`
    /// (N): F_z·μ·μ_surface·λ(F_z), as simuv2's `wheel.cpp` has it per wheel.
    #[inline(always)]
    pub fn wheel_max_force(&self, fz: f64, surface: f64) -> f64 {
        fz * self.mu * surface * self.load_factor(fz)
    }

    /// Largest force an axle of two such tyres can give under its load `fz` on a surface of
    /// friction `surface` (N): F_z·μ·μ_surface·λ(F_z/2).
    #[inline]
    pub fn axle_max_force(&self, fz: f64, surface: f64) -> f64 {
        fz * self.mu * surface * self.load_factor(0.5 * fz)
    }

    /// g(u) = f(√u)/√u and g′(u) for u = s² ≥ 0: the tabulated values up to u = 1, the
    /// formula beyond.
    #[inline(always)]
    pub fn ratio(&self, u: f64) -> (f64, f64) {
        self.ratio_table
            .eval(u)
            .unwrap_or_else(|| self.ratio_exact(u))
    }

    /// g(u) = f(√u)/√u and g′(u) = (f′(s)·s − f(s))/(2s³), evaluated directly; below
    /// u = 1e-8 from the series f(s) = BC·s + a₃s³ + O(s⁵), g = BC + a₃u, with
    /// a₃ = −B³C(1 + E)/3 − (BC)³/6.
    pub fn ratio_exact(&self, u: f64) -> (f64, f64) {
        let (b, c) = (self.b, self.c);
        let a3 = -b.powi(3) * c * (1.0 + self.e) / 3.0 - (b * c).powi(3) / 6.0;
        if u < 1e-8 {
            return (b * c + a3 * u, a3);
        }
        let s = u.sqrt();
        let (f, df) = self.shape_exact(s);
        (f / s, (df * s - f) / (2.0 * u * s))
    }

    /// The Magic-Formula shape f(s) = sin(C·atan(B·s·(1 − E) + E·atan(B·s))) and its
    /// derivative df/ds, evaluated directly.
    pub fn shape_exact(&self, s: f64) -> (f64, f64) {
        let bs = self.b * s;
        let inner = bs * (1.0 - self.e) + self.e * bs.atan();
        let arg = self.c * inner.atan();
        let (sin, cos) = arg.sin_cos();
        let dinner = self.b * ((1.0 - self.e) + self.e / (1.0 + bs * bs));
        (sin, cos * self.c / (1.0 + inner * inner) * dinner)
    }

    /// Forces for slip (sₓ, s_y) with grip budget `fmax` = F_z·μ·μ_r·λ, and their
    /// derivatives with respect to sₓ, with u = sₓ² + s_y²:
    /// Fₓ = fmax·g(u)·sₓ, F_y = fmax·g(u)·s_y,
    /// ∂Fₓ/∂sₓ = fmax·[g + 2sₓ²·g′], ∂F_y/∂sₓ = fmax·2sₓs_y·g′.
    #[inline(always)]
    pub fn forces(&self, sx: f64, sy: f64, fmax: f64) -> Forces {
        let u = sx * sx + sy * sy;
        let [fx, fy, dfx_dsx, dfy_dsx] = forces_of(fmax, self.ratio(u), u, (sx, sy), self.skid);
        Forces {
            fx,
            fy,
            dfx_dsx,
            dfy_dsx,
        }
    }

    /// [`TyreModel::wheel_max_force`] of four tyres side by side, `tyres[i]` under `fz[i]` on
    /// `surface[i]`, bit for bit, in vector registers ([`F64x4`]); each lane by the formula
    /// past its table.
    #[inline(always)]
    pub(crate) fn wheel_max_force_lanes(
        tyres: [&TyreModel; 4],
        fz: F64x4,
        surface: F64x4,
    ) -> F64x4 {
        let z = fz * F64x4::new(tyres.map(|t| t.inv_operating_load));
        let load_factor = match HermiteTable::eval_lanes(tyres.map(|t| &t.load_table), z) {
            Some((l, _)) => l,
            None => {
                let fz = fz.to_array();
                F64x4::new(std::array::from_fn(|i| tyres[i].load_factor(fz[i])))
            }
        };
        fz * F64x4::new(tyres.map(|t| t.mu)) * surface * load_factor
    }

    /// [`TyreModel::forces`] of four tyres side by side, `tyres[i]` at slip (`sx[i]`, `sy[i]`)
    /// under `fmax[i]`, bit for bit, in vector registers ([`F64x4`]); each lane by the formula
    /// past its table.
    #[inline(always)]
    pub(crate) fn forces_lanes(
        tyres: [&TyreModel; 4],
        sx: F64x4,
        sy: F64x4,
        fmax: F64x4,
    ) -> [Forces; 4] {
        let u = sx * sx + sy * sy;
        let ratio = match HermiteTable::eval_lanes(tyres.map(|t| &t.ratio_table), u) {
            Some(table) => table,
            None => {
                let u = u.to_array();
                let exact: [(f64, f64); 4] = std::array::from_fn(|i| tyres[i].ratio(u[i]));
                (
                    F64x4::new(exact.map(|r| r.0)),
                    F64x4::new(exact.map(|r| r.1)),
                )
            }
        };
        let skid = F64x4::new(tyres.map(|t| t.skid));
        let [fx, fy, dfx_dsx, dfy_dsx] = forces_of(fmax, ratio, u, (sx, sy), skid);
        let [fx, fy, dfx_dsx, dfy_dsx] = [fx, fy, dfx_dsx, dfy_dsx].map(F64x4::to_array);
        std::array::from_fn(|i| Forces {
            fx: fx[i],
            fy: fy[i],
            dfx_dsx: dfx_dsx[i],
            dfy_dsx: dfy_dsx[i],
        })
    }

    /// The skid factor's multiplier m(u) = 1 + k·min(√u, [`SKID_SLIP_CAP`]) and dm/du.
    #[inline(always)]
    pub fn skid_multiplier(&self, u: f64) -> (f64, f64) {
        skid_multiplier(u, self.skid)
    }

    fn find_peak_slip(&self) -> f64 {
        // The shape rises monotonically to its peak: bisect on the sign of df/ds.
        let (mut lo, mut hi) = (0.0, 5.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.shape_exact(mid).1 > 0.0 {
                lo = mid
            } else {
                hi = mid
            }
        }
        0.5 * (lo + hi)
    }
}

/// Tyre forces (N) and their sensitivity to longitudinal slip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Forces {
    /// Longitudinal force, along the wheel.
    pub fx: f64,
    /// Lateral force.
    pub fy: f64,
    /// ∂Fₓ/∂sₓ.
    pub dfx_dsx: f64,
    /// ∂F_y/∂sₓ.
    pub dfy_dsx: f64,
}

/// [Fₓ, F_y, ∂Fₓ/∂sₓ, ∂F_y/∂sₓ] ([`TyreModel::forces`]) at slip (sₓ, s_y) = `slip`, u = sₓ² + s_y²,
/// under the budget `fmax`, with the shape's ratio (g, g′) at u and the skid factor k = `skid`
/// (none at 0): with one, g·m and g′·m + g·m′ for its multiplier m(u)
/// ([`TyreModel::skid_multiplier`]): where any lane has one, both are computed and each lane
/// keeps its own, without branches; where none has, the multiplier is not computed.
#[inline(always)]
fn forces_of<T: Lane>(fmax: T, (g, dg): (T, T), u: T, (sx, sy): (T, T), skid: T) -> [T; 4] {
    let skidding = skid.gt(T::splat(0.0));
    let (g, dg) = if skidding.any() {
        let (m, dm) = skid_multiplier(u, skid);
        (
            T::select(skidding, g * m, g),
            T::select(skidding, dg * m + g * dm, dg),
        )
    } else {
        (g, dg)
    };
    let (fg, two_dg_sx) = (fmax * g, fmax * T::splat(2.0) * dg * sx);
    [fg * sx, fg * sy, fg + two_dg_sx * sx, two_dg_sx * sy]
}

/// The skid factor k's multiplier m(u) = 1 + k·min(√u, [`SKID_SLIP_CAP`]) and dm/du = k/(2√u)
/// below the cap (0 at u = 0 and past the cap): each case computed and the one for √u kept,
/// without branches.
#[inline(always)]
fn skid_multiplier<T: Lane>(u: T, skid: T) -> (T, T) {
    let (zero, one, cap) = (T::splat(0.0), T::splat(1.0), T::splat(SKID_SLIP_CAP));
    let s = u.sqrt();
    let (capped, rising) = (s.ge(cap), s.gt(zero));
    let m = T::select(rising, one + skid * s, one);
    let dm = T::select(rising, T::splat(0.5) * skid / s, zero);
    (
        T::select(capped, one + skid * cap, m),
        T::select(capped, zero, dm),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::car::{Car, Tyre};

    #[test]
    fn shape_constants_follow_torcs() {
        let m = TyreModel::new(&Car::spirit_300().rear_tyre);
        let c = 2.0 - 0.6f64.asin() * 2.0 / std::f64::consts::PI;
        assert!((m.c - c).abs() < 1e-12 && (m.b - 16.0 / c).abs() < 1e-12);
        // The peak is 1 (sin = 1) and beyond it the force falls to the dynamic level.
        assert!((m.shape_exact(m.peak_slip).0 - 1.0).abs() < 1e-9);
        assert!(m.shape_exact(1.0).0 < 0.95);
    }

    #[test]
    fn force_derivatives_match_finite_differences_and_share_one_budget() {
        let m = TyreModel::new(&Car::spirit_300().rear_tyre);
        for (sx, sy) in [
            (0.02, 0.0),
            (0.1, 0.05),
            (-0.3, 0.2),
            (0.5, -0.4),
            (0.0, 0.1),
        ] {
            let f = m.forces(sx, sy, 5000.0);
            let h = 1e-7;
            let (p, q) = (m.forces(sx + h, sy, 5000.0), m.forces(sx - h, sy, 5000.0));
            assert!(
                (f.dfx_dsx - (p.fx - q.fx) / (2.0 * h)).abs() < 1e-3 * f.dfx_dsx.abs().max(1.0)
            );
            assert!(
                (f.dfy_dsx - (p.fy - q.fy) / (2.0 * h)).abs() < 1e-3 * f.dfx_dsx.abs().max(1.0)
            );
            assert!(f.fx.hypot(f.fy) <= 5000.0 + 1e-9);
        }
    }

    /// simuv2's skid factor k: the force is f(s)·(1 + k·min(s, 1.5)), its derivatives follow,
    /// the force's cap is the largest such value (1.45·f(1.5) for car1-trb1's shape), and
    /// without the factor the cap is 1 and the peak slip the shape's own.
    #[test]
    fn the_skid_factor_grows_the_force_with_the_slip() {
        let plain = Car::spirit_300().rear_tyre;
        let skid = TyreModel::new(&Tyre { skid: 0.3, ..plain });
        let plain = TyreModel::new(&plain);
        assert_eq!(plain.force_cap, 1.0);
        assert_eq!(skid.peak_slip, plain.peak_slip);
        for (sx, sy) in [
            (0.05, 0.0),
            (0.2, 0.1),
            (-0.7, 0.3),
            (1.2, -1.0),
            (2.0, 0.0),
        ] {
            let s: f64 = f64::hypot(sx, sy);
            let f = skid.forces(sx, sy, 1000.0);
            let want = 1000.0 * skid.shape_exact(s).0 * (1.0 + 0.3 * s.min(1.5));
            assert!((f.fx.hypot(f.fy) - want).abs() < 1e-6 * want, "{s}");
            assert!(f.fx.hypot(f.fy) <= 1000.0 * skid.force_cap + 1e-9);
            let h = 1e-7;
            let (p, q) = (
                skid.forces(sx + h, sy, 1000.0),
                skid.forces(sx - h, sy, 1000.0),
            );
            let scale = f.dfx_dsx.abs().max(1.0);
            assert!(
                (f.dfx_dsx - (p.fx - q.fx) / (2.0 * h)).abs() < 1e-3 * scale,
                "{s}"
            );
            assert!(
                (f.dfy_dsx - (p.fy - q.fy) / (2.0 * h)).abs() < 1e-3 * scale,
                "{s}"
            );
        }
        let torcs = TyreModel::new(&Tyre {
            stiffness: 20.0,
            dynamic_friction: 0.8,
            elasticity: 0.7,
            skid: 0.3,
            ..Car::spirit_300().rear_tyre
        });
        let at_cap = torcs.shape_exact(1.5).0 * 1.45;
        assert!(
            (torcs.force_cap - at_cap).abs() < 1e-9,
            "{}",
            torcs.force_cap
        );
    }

    /// The lanes of [`TyreModel::forces_lanes`] and [`TyreModel::wheel_max_force_lanes`] give
    /// each tyre's own forces and budget bit for bit, inside the tables and past them.
    #[test]
    fn four_tyres_side_by_side_are_four_tyres() {
        use rand::Rng;
        let skidding = Tyre {
            skid: 0.3,
            ..Car::spirit_300().rear_tyre
        };
        let models = [
            TyreModel::new(&Car::spirit_300().front_tyre),
            TyreModel::new(&Car::spirit_300().rear_tyre),
            TyreModel::new(&skidding),
        ];
        let mut rng = crate::rng::rng_for(9, 0);
        for n in 0..40_000 {
            let tyres: [&TyreModel; 4] = std::array::from_fn(|_| &models[rng.random_range(0..3)]);
            // Slips past the table's end (s = 1) and loads past 8 operating loads in some.
            let reach = if n % 10 == 0 { 2.0 } else { 0.6 };
            let sx: [f64; 4] = std::array::from_fn(|_| rng.random_range(-reach..reach));
            let sy: [f64; 4] = std::array::from_fn(|_| rng.random_range(-reach..reach));
            let top = if n % 10 == 1 { 40_000.0 } else { 8000.0 };
            let fz: [f64; 4] = std::array::from_fn(|_| rng.random_range(0.0..top));
            let surface: [f64; 4] = std::array::from_fn(|_| rng.random_range(0.3..1.2));
            let fmax = TyreModel::wheel_max_force_lanes(tyres, F64x4::new(fz), F64x4::new(surface))
                .to_array();
            let forces =
                TyreModel::forces_lanes(tyres, F64x4::new(sx), F64x4::new(sy), F64x4::new(fmax));
            for i in 0..4 {
                let one = tyres[i].wheel_max_force(fz[i], surface[i]);
                assert_eq!(fmax[i].to_bits(), one.to_bits(), "{} N", fz[i]);
                let one = tyres[i].forces(sx[i], sy[i], fmax[i]);
                let bits = |f: Forces| [f.fx, f.fy, f.dfx_dsx, f.dfy_dsx].map(f64::to_bits);
                assert_eq!(bits(forces[i]), bits(one), "({}, {})", sx[i], sy[i]);
            }
        }
    }

    #[test]
    fn the_table_matches_the_formula() {
        let m = TyreModel::new(&Car::spirit_300().rear_tyre);
        for i in 0..30_000 {
            // Slips up to 1.5, past the table's end at s = 1, denser near the peak.
            let s = (i as f64 / 30_000.0).powi(2) * 1.5 + 3.3e-6;
            let (g, dg) = m.ratio(s * s);
            let (f, df) = m.shape_exact(s);
            assert!((g * s - f).abs() < 2e-10, "f at {s}: {} vs {f}", g * s);
            // f′(s) = g + 2u·g′ (from f = √u·g).
            let slope = g + 2.0 * s * s * dg;
            assert!(
                (slope - df).abs() < 1e-6 * df.abs().max(1.0),
                "f' at {s}: {slope} vs {df}"
            );
        }
        // The series just below u = 1e-8 joins the formula just above it: g moves by g′·Δu.
        let (near, exact) = (m.ratio_exact(0.99e-8), m.ratio_exact(1.01e-8));
        assert!((near.0 + near.1 * 0.02e-8 - exact.0).abs() < 1e-10);
        assert!((near.1 - exact.1).abs() < 1e-5 * exact.1.abs());
    }

    #[test]
    fn load_sensitivity_is_one_at_the_operating_load() {
        let m = TyreModel::new(&Car::spirit_300().rear_tyre);
        for i in 0..10_000 {
            let fz = i as f64 * 3.7;
            let exact = LOAD_FACTOR_MIN
                + (LOAD_FACTOR_MAX - LOAD_FACTOR_MIN) * (m.load_k * fz / m.operating_load).exp();
            assert!((m.load_factor(fz) - exact).abs() < 1e-11);
        }
        assert!((m.load_factor(m.operating_load) - 1.0).abs() < 1e-12);
        assert!((m.load_factor(0.0) - LOAD_FACTOR_MAX).abs() < 1e-12);
        assert!(m.load_factor(2.0 * m.operating_load) < 1.0);
    }

    #[test]
    fn shape_derivative_matches_finite_differences() {
        let m = TyreModel::new(&Car::spirit_300().front_tyre);
        for s in [0.0, 0.01, 0.05, 0.1, 0.3, 1.0] {
            let h = 1e-7;
            let fd = (m.shape_exact(s + h).0 - m.shape_exact(s - h).0) / (2.0 * h);
            assert!(
                (fd - m.shape_exact(s).1).abs() < 1e-5 * fd.abs().max(1.0),
                "s {s}: {fd} vs {}",
                m.shape_exact(s).1
            );
        }
    }
}
