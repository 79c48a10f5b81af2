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

/// `x^(10/9)` for `x > 0` as `x cbrt(cbrt x)` (within 2 ulp of the exact value).
#[inline]
pub fn pow_10_9(x: f64) -> f64 {
    x * cbrt(cbrt(x))
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
        let mut worst = (0, 0);
        for x in samples(1e-14, 1e6, 300_000) {
            let a = ulps(pow_10_9(x), exact_power(x, 10.0, 9.0));
            let b = ulps(pow_2_3(x), exact_power(x, 2.0, 3.0));
            worst = (worst.0.max(a), worst.1.max(b));
        }
        // The reference is itself good to about one ulp (powf, then one product).
        assert!(worst.0 <= 3 && worst.1 <= 2, "worst ulps {worst:?}");
    }
}
