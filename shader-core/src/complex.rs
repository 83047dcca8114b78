//! A tiny complex number type on two f32 values, for the conductor Fresnel equations
//! (PBRT-v4 `pstd::complex`, section 9.3.6) written with correctly rounded real operations only.
//!
//! Conventions: NaN components propagate; division uses Smith's algorithm (no premature overflow
//! of c^2 + d^2); `abs` is a scaled hypot (no overflow or underflow of the squares); `sqrt` is the
//! principal branch (re >= 0), as PBRT's `pstd::sqrt`.
//!
//! ```
//! use shader_core::complex::{hypot, Complex};
//! // The principal square root of -4 is 2i (re >= 0).
//! assert_eq!(Complex::new(-4.0, 0.0).sqrt(), Complex::new(0.0, 2.0));
//! // Smith's division: (1 + 2i) / (1 + 2i) = 1 exactly.
//! let z = Complex::new(1.0, 2.0);
//! assert_eq!(z / z, Complex::new(1.0, 0.0));
//! // hypot does not overflow where re^2 + im^2 would.
//! let s = 2.0f32.powi(100);
//! assert_eq!(hypot(3.0 * s, 4.0 * s), 5.0 * s);
//! assert!(Complex::new(3.0 * s, 4.0 * s).norm().is_infinite());
//! ```

use crate::ieee;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// `re + i im`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Complex {
    /// Real part.
    pub re: f32,
    /// Imaginary part.
    pub im: f32,
}

impl Complex {
    /// The complex number `re + i im`, stored as given.
    #[inline]
    pub const fn new(re: f32, im: f32) -> Self {
        Complex { re, im }
    }

    /// A real number as a complex one (im = +0).
    #[inline]
    pub const fn real(re: f32) -> Self {
        Complex { re, im: 0.0 }
    }

    /// Squared magnitude re^2 + im^2 (PBRT's `pstd::norm`).
    #[inline]
    pub fn norm(self) -> f32 {
        self.re * self.re + self.im * self.im
    }

    /// Magnitude |z| = hypot(re, im), scaled by the larger component so the squares cannot
    /// overflow or underflow. NaN if either part is NaN, except |inf + i NaN| = inf (IEEE hypot).
    #[inline]
    pub fn abs(self) -> f32 {
        hypot(self.re, self.im)
    }

    /// Principal square root (PBRT-v4 `pstd::sqrt(complex)`): with n = |z|,
    /// t1 = sqrt((n + |re|) / 2), t2 = im / (2 t1); re >= 0 gives (t1, t2), re < 0 gives
    /// (|t2|, copysign(t1, im)). sqrt(0) = 0.
    #[inline]
    pub fn sqrt(self) -> Complex {
        let n = self.abs();
        if n == 0.0 {
            return Complex::real(0.0);
        }
        let t1 = ieee::sqrt(0.5 * (n + self.re.abs()));
        let t2 = ieee::div(0.5 * self.im, t1);
        if self.re >= 0.0 {
            Complex::new(t1, t2)
        } else if self.im.is_sign_negative() {
            Complex::new(t2.abs(), -t1)
        } else {
            Complex::new(t2.abs(), t1)
        }
    }

    /// Multiply by a real number.
    #[inline]
    pub fn scale(self, s: f32) -> Complex {
        Complex::new(self.re * s, self.im * s)
    }
}

/// hypot(a, b) = m sqrt(1 + (n/m)^2) with m = max(|a|, |b|), n = min(|a|, |b|); exact zero for (0, 0).
#[inline]
pub fn hypot(a: f32, b: f32) -> f32 {
    let x = a.abs();
    let y = b.abs();
    let (m, n) = if x >= y { (x, y) } else { (y, x) };
    if m == f32::INFINITY {
        return m;
    }
    if m == 0.0 {
        // (0, 0) -> 0; (0, NaN) or (NaN, 0) -> NaN.
        return n + m;
    }
    let r = ieee::div(n, m);
    m * ieee::sqrt(1.0 + r * r)
}

impl Add for Complex {
    type Output = Complex;
    #[inline]
    fn add(self, o: Complex) -> Complex {
        Complex::new(self.re + o.re, self.im + o.im)
    }
}

impl Sub for Complex {
    type Output = Complex;
    #[inline]
    fn sub(self, o: Complex) -> Complex {
        Complex::new(self.re - o.re, self.im - o.im)
    }
}

impl Neg for Complex {
    type Output = Complex;
    #[inline]
    fn neg(self) -> Complex {
        Complex::new(-self.re, -self.im)
    }
}

impl Mul for Complex {
    type Output = Complex;
    /// (a + ib)(c + id) = (ac - bd) + i(ad + bc), each product rounded separately (no fma).
    #[inline]
    fn mul(self, o: Complex) -> Complex {
        Complex::new(self.re * o.re - self.im * o.im, self.re * o.im + self.im * o.re)
    }
}

impl Div for Complex {
    type Output = Complex;
    /// Smith's algorithm (Smith 1962, "Algorithm 116: Complex division"): divide through by the
    /// larger of |c|, |d| so c^2 + d^2 is never formed. Division by zero gives non-finite parts.
    #[inline]
    fn div(self, o: Complex) -> Complex {
        let (a, b, c, d) = (self.re, self.im, o.re, o.im);
        if c.abs() >= d.abs() {
            let r = ieee::div(d, c);
            let den = c + d * r;
            Complex::new(ieee::div(a + b * r, den), ieee::div(b - a * r, den))
        } else {
            let r = ieee::div(c, d);
            let den = c * r + d;
            Complex::new(ieee::div(a * r + b, den), ieee::div(b * r - a, den))
        }
    }
}
