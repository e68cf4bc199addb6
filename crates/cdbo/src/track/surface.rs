//! What a wheel stands on: a surface's friction, rolling resistance and roughness, the
//! bumps it meets, and what lies past the road's edges.

/// A surface a wheel can stand on: its TORCS `friction`, `rolling resistance` (`None`: the
/// car's tyres give the rolling resistance) and roughness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// Friction coefficient, scales the tyre's grip.
    pub friction: f64,
    /// Rolling resistance coefficient, F = c_rr·F_z, if the track gives one.
    pub rolling_resistance: Option<f64>,
    /// Its roughness.
    pub roughness: Roughness,
}

impl Surface {
    /// Friction 1, the tyres' rolling resistance, smooth.
    pub const PLAIN: Surface = Surface {
        friction: 1.0,
        rolling_resistance: None,
        roughness: Roughness::NONE,
    };
}

/// A surface's roughness as TORCS's simuv2 lays it under the wheels (`RtTrackHeightL`): the
/// ground under a wheel at distance l along its segment and t across it (from the segment's
/// right edge) stands h = A·sin(k·t)·sin(k·l) above the smooth surface, A = R/2 and k = 2π/λ
/// of the file's `roughness` R and `roughness wavelength` λ (`track4.cpp`: `kRoughness`,
/// `kRoughWaveLen`). Most roads are smooth; Aalborg's is R = 0.7 to 1.5 cm at λ = 0.7 to
/// 0.9 m in places, G-Track 1's 1 cm at 1 m; grass is 5 cm at 0.5 m. The wheels' bounce over
/// a rough road ([`crate::vehicle::bounce`]) costs grip.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Roughness {
    /// Amplitude A (m).
    pub amplitude: f64,
    /// Wavenumber k (rad/m).
    pub wavenumber: f64,
}

impl Roughness {
    /// A smooth surface.
    pub const NONE: Roughness = Roughness {
        amplitude: 0.0,
        wavenumber: 0.0,
    };

    /// From a file's `roughness` R and `roughness wavelength` λ > 0 (m): A = R/2, k = 2π/λ.
    pub fn from_file(roughness: f64, wavelength: f64) -> Roughness {
        Roughness {
            amplitude: 0.5 * roughness,
            wavenumber: std::f64::consts::TAU / wavelength,
        }
    }

    /// Whether it is rough enough to feel: an amplitude of [`FELT_ROUGHNESS_M`] or more.
    #[inline]
    pub fn is_rough(&self) -> bool {
        self.amplitude >= FELT_ROUGHNESS_M
    }

    /// The bumps a wheel meets along its path on this surface, t metres across it from its
    /// right edge (a plain surface: A·sin(k·t) is the amplitude along), l metres along.
    #[inline]
    pub fn plain(&self, along: f64, across: f64) -> Bumps {
        Bumps {
            amplitude: self.amplitude * (self.wavenumber * across).sin(),
            wavenumber: self.wavenumber,
            along,
            kink: 0.0,
            kink_slope: 0.0,
        }
    }
}

/// The smallest amplitude A of a surface's roughness cdbo's car feels (m): half a millimetre.
/// Below it the wheels' bounce takes less than 0.2 % of their grip up to 80 m/s (E-Track 2's
/// and E-Track 3's roads, A = 0.25 mm at λ = 2 m) and would triple the cost of the physics
/// step on those tracks; at A = 0.5 mm it takes 0.7 % at 80 m/s (car1-trb1 at λ of 1 to 2 m),
/// at Aalborg's 7.5 mm (λ = 0.7 m) 6 % at 20 m/s and 12 % at 60 to 80 m/s.
pub const FELT_ROUGHNESS_M: f64 = 0.0005;

/// The ground's height along a wheel's path above the road's smoothed profile, h(δ) =
/// a·sin(k·(l + δ)) + k₀ + k′·δ at δ metres past where the wheel stands (l along the surface):
/// a rough surface's bumps ([`Roughness::plain`] at the wheel's place) and the road's kink
/// there ([`Frame::kink_at`](super::Frame::kink_at)).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Bumps {
    /// The amplitude a (m) across the wheel's path.
    pub amplitude: f64,
    /// The wavenumber k (rad/m).
    pub wavenumber: f64,
    /// Where the wheel stands along the surface, l (m).
    pub along: f64,
    /// The road's kink under the wheel, k (m, [`Frame::kink_at`](super::Frame::kink_at)).
    pub kink: f64,
    /// Its slope along the wheel's path, k′ (m/m).
    pub kink_slope: f64,
}

impl Bumps {
    /// None: a smooth surface.
    pub const NONE: Bumps = Bumps {
        amplitude: 0.0,
        wavenumber: 0.0,
        along: 0.0,
        kink: 0.0,
        kink_slope: 0.0,
    };

    /// Whether there is anything under the wheel.
    #[inline]
    pub fn any(&self) -> bool {
        self.amplitude != 0.0 || self.kink != 0.0 || self.kink_slope != 0.0
    }

    /// h(δ) (m).
    #[inline]
    pub fn height(&self, ahead: f64) -> f64 {
        let kink = self.kink + self.kink_slope * ahead;
        if self.amplitude == 0.0 {
            return kink;
        }
        kink + self.amplitude * (self.wavenumber * (self.along + ahead)).sin()
    }
}

/// What lies past one edge of the road, as TORCS's `track4.cpp` builds it (`AddSides`): next
/// to the road a border (`Left Border` / `Right Border`: `width`, `surface`; a kerb, a strip of
/// grass), then a side (`Left Side` / `Right Side`: `start width` … `end width`, `surface`;
/// grass, gravel, a run-off), then the barrier. simuv2 finds each wheel's segment (road, border
/// or side) under the wheel's centre (`wheel.cpp`: `RtTrackGlobal2Local` of the wheel's
/// position) and takes that segment's surface's `kFriction` and `kRollRes` for the wheel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verge {
    /// Width of the border (m); 0 without one.
    pub border_width: f64,
    /// The border's surface.
    pub border: Surface,
    /// How high a kerb the border is (m; its `height` where its `style` is `curb`, else 0):
    /// TORCS raises the kerb's outer edge by it, a ramp cdbo's wheels do not climb.
    pub kerb_height: f64,
    /// Width of the side past the border (m); 0 without one.
    pub side_width: f64,
    /// The side's surface.
    pub side: Surface,
    /// Whether a barrier stands past the side (TORCS version-4 files: `track4.cpp` closes
    /// every side with one), at half the road's width plus the border's and the side's from
    /// the centre line; simuv2 collides the body's corners with it (`collide.cpp`).
    pub barrier: bool,
}

impl Verge {
    /// No border and no side: the road's surface is taken on past its edge (the built-in and
    /// CSV tracks, TORCS version-3 files).
    pub const NONE: Verge = Verge {
        border_width: 0.0,
        border: Surface::PLAIN,
        kerb_height: 0.0,
        side_width: 0.0,
        side: Surface::PLAIN,
        barrier: false,
    };

    /// The surface `excess` metres past the road's edge (excess > 0): the border's within its
    /// width, then the side's; past the side (at the barrier) the side's, or the border's when
    /// there is no side; `None` (the road's) when there is neither.
    #[inline]
    pub fn surface_at(&self, excess: f64) -> Option<&Surface> {
        if self.border_width > 0.0 && (excess <= self.border_width || self.side_width <= 0.0) {
            Some(&self.border)
        } else if self.side_width > 0.0 {
            Some(&self.side)
        } else {
            None
        }
    }
}
