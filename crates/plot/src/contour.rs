//! Contour lines of a value over a rectilinear grid: marching squares, and round levels
//! to draw them at.

/// Contour segments of `z` at `level` by marching squares.
///
/// `z[j * xs.len() + i]` is the value at `(xs[i], ys[j])`. Cells with a non-finite corner are
/// skipped; saddles are resolved by the cell's mean. Crossings are interpolated linearly, and
/// a crossing shared by two cells is computed identically in both, so closed contours join
/// exactly.
pub fn marching_squares(xs: &[f64], ys: &[f64], z: &[f64], level: f64) -> Vec<[(f64, f64); 2]> {
    let (nx, ny) = (xs.len(), ys.len());
    let mut out = Vec::new();
    if nx < 2 || ny < 2 || z.len() < nx * ny || !level.is_finite() {
        return out;
    }
    let at = |i: usize, j: usize| z[j * nx + i];
    let cross = |p: (f64, f64, f64), q: (f64, f64, f64)| {
        let t = (level - p.2) / (q.2 - p.2);
        (p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1))
    };
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            // a bottom-left, b bottom-right, c top-right, d top-left.
            let a = (xs[i], ys[j], at(i, j));
            let b = (xs[i + 1], ys[j], at(i + 1, j));
            let c = (xs[i + 1], ys[j + 1], at(i + 1, j + 1));
            let d = (xs[i], ys[j + 1], at(i, j + 1));
            if ![a.2, b.2, c.2, d.2].iter().all(|v| v.is_finite()) {
                continue;
            }
            let inside = |p: (f64, f64, f64)| p.2 >= level;
            let (ia, ib, ic, id) = (inside(a), inside(b), inside(c), inside(d));
            let bottom = (ia != ib).then(|| cross(a, b));
            let right = (ib != ic).then(|| cross(b, c));
            let top = (id != ic).then(|| cross(d, c));
            let left = (ia != id).then(|| cross(a, d));
            let hits: Vec<(f64, f64)> = [bottom, right, top, left].into_iter().flatten().collect();
            match hits.len() {
                2 => out.push([hits[0], hits[1]]),
                4 => {
                    let centre = (a.2 + b.2 + c.2 + d.2) / 4.0 >= level;
                    let (bo, r, t, l) = (hits[0], hits[1], hits[2], hits[3]);
                    if centre == ia {
                        // a and c connected through the centre: cut off b and d.
                        out.push([bo, r]);
                        out.push([t, l]);
                    } else {
                        out.push([l, bo]);
                        out.push([r, t]);
                    }
                }
                _ => {}
            }
        }
    }
    out
}

/// About `target` round contour levels strictly inside (lo, hi).
pub fn nice_levels(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) || target == 0 {
        return Vec::new();
    }
    let raw = span / target as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let start = (lo / step).floor() * step;
    // Bounded, so a step too small to move a huge start cannot loop forever.
    (0..=target * 3 + 2)
        .map(|k| start + k as f64 * step)
        .filter(|v| *v > lo + span * 1e-6 && *v < hi - span * 1e-6)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marching_squares_rings_a_cone() {
        let n = 41;
        let xs: Vec<f64> = (0..n)
            .map(|i| -2.0 + 4.0 * i as f64 / (n - 1) as f64)
            .collect();
        let ys = xs.clone();
        let z: Vec<f64> = (0..n * n)
            .map(|k| {
                let (x, y) = (xs[k % n], ys[k / n]);
                (x * x + y * y).sqrt()
            })
            .collect();
        // Levels off the grid nodes' radii (a node exactly on a level is a degenerate touch).
        for r in [0.55, 1.05, 1.45] {
            let segs = marching_squares(&xs, &ys, &z, r);
            assert!(segs.len() > 8, "{r}: {}", segs.len());
            // Every point lies near the circle of radius r.
            for s in &segs {
                for p in s {
                    let d = (p.0 * p.0 + p.1 * p.1).sqrt();
                    assert!((d - r).abs() < 0.01, "level {r}: point at {d}");
                }
            }
            // Closed: every endpoint is shared by exactly two segments.
            let ends: Vec<(f64, f64)> = segs.iter().flat_map(|s| [s[0], s[1]]).collect();
            for p in &ends {
                let k = ends
                    .iter()
                    .filter(|q| (q.0 - p.0).abs() < 1e-12 && (q.1 - p.1).abs() < 1e-12)
                    .count();
                assert_eq!(k, 2, "level {r}: open end at {p:?}");
            }
            // And it goes all the way round.
            let mut quadrants = [false; 4];
            for p in &ends {
                quadrants[(p.0 >= 0.0) as usize * 2 + (p.1 >= 0.0) as usize] = true;
            }
            assert!(quadrants.iter().all(|q| *q));
        }
        // NaN cells are skipped; a level outside the data gives nothing.
        let mut z2 = z.clone();
        z2.iter_mut().for_each(|v| *v = f64::NAN);
        assert!(marching_squares(&xs, &ys, &z2, 1.0).is_empty());
        assert!(marching_squares(&xs, &ys, &z, 10.0).is_empty());
    }

    #[test]
    fn marching_squares_saddle_gives_two_segments() {
        let xs = [0.0, 1.0];
        let ys = [0.0, 1.0];
        let z = [1.0, 0.0, 0.0, 1.0]; // a, b / d, c: diagonal highs
        assert_eq!(marching_squares(&xs, &ys, &z, 0.5).len(), 2);
    }

    #[test]
    fn levels_are_round_and_inside() {
        assert_eq!(nice_levels(0.0, 10.0, 5), vec![2.0, 4.0, 6.0, 8.0]);
        let l = nice_levels(123.0, 987.0, 6);
        assert!(
            l.iter().all(|v| *v > 123.0 && *v < 987.0) && l.len() >= 4,
            "{l:?}"
        );
        assert!(nice_levels(1.0, 1.0, 5).is_empty());
    }
}
