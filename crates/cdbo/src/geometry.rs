//! Plane geometry the lines and the steering read: angles wrapped into (−π, π] and where a
//! point lies from the car's heading.

/// The angle (rad, in (−π, π]) from a heading (cos ψ, sin ψ), given as `yaw_sin_cos`
/// = (sin ψ, cos ψ), to the vector (dx, dy): atan2(cos ψ·dy − sin ψ·dx, cos ψ·dx + sin ψ·dy).
#[inline]
pub fn bearing(dx: f64, dy: f64, yaw_sin_cos: (f64, f64)) -> f64 {
    let (sy, cy) = yaw_sin_cos;
    (cy * dy - sy * dx).atan2(cy * dx + sy * dy)
}

/// An angle wrapped into (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    let t = (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    if t == -std::f64::consts::PI {
        std::f64::consts::PI
    } else {
        t
    }
}
