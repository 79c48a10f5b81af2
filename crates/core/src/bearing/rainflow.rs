//! Rainflow cycle counting, ASTM E1049-85 (reapproved 2017), *Standard Practices for Cycle
//! Counting in Fatigue Analysis*, § 5.4.4 (the three-point rule with the starting point `S`,
//! usually drawn as the four-point method), streaming.
//!
//! The standard's rules, as implemented in [`Rainflow::push`] and [`Rainflow::finish`]:
//! 1. Read the next peak or valley; out of data, go to 6.
//! 2. Fewer than three points: go to 1. Form `X`, the most recent range, and `Y`, the range
//!    before it, from the three most recent points not discarded.
//! 3. `X < Y`: go to 1.
//! 4. `Y` contains the starting point `S`: go to 5. Otherwise count `Y` as one cycle,
//!    discard both its points, and go to 2.
//! 5. Count `Y` as one half cycle, discard its first point (`S`), make its second point the
//!    new `S`, and go to 2.
//! 6. Count each range not yet counted as one half cycle (the residue).
//!
//! The input is any sequence of values: equal neighbours and non-reversing points are merged
//! into the peaks and valleys (the standard's first step), the first and the last values are
//! reversals.
//!
//! Memory: the points kept are the residue, whose ranges strictly decrease from `S` (rule 3
//! keeps a point only while `X < Y`), so a history that returns to its extremes keeps few.
//! A long converging history (a decaying ring-down) keeps one point per reversal; the kept
//! points are capped at [`Rainflow::DEFAULT_STACK_LIMIT`]: past it the oldest range is
//! counted as a half cycle and `S` moves on, as if the history were cut there (documented,
//! and counted in [`Rainflow::truncations`]).

use serde::{Deserialize, Serialize};

/// A counted range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cycle {
    /// Range, `|max - min|`, in the units of the input.
    pub range: f64,
    /// Mean `(max + min) / 2`.
    pub mean: f64,
    /// 1 for a full cycle, 0.5 for a half cycle.
    pub count: f64,
}

/// A streaming rainflow counter (ASTM E1049 § 5.4.4).
#[derive(Debug, Clone, PartialEq)]
pub struct Rainflow {
    /// Reversals not yet discarded; `points[0]` is the starting point `S`.
    points: Vec<f64>,
    /// The running extreme since the last reversal, not yet known to be a reversal.
    candidate: Option<f64>,
    /// Direction from the last reversal to the candidate: +1 rising, -1 falling, 0 unknown.
    direction: i8,
    stack_limit: usize,
    truncations: u64,
}

impl Default for Rainflow {
    fn default() -> Self {
        Rainflow::new()
    }
}

impl Rainflow {
    /// Reversals kept at most before the oldest range is counted as a half cycle.
    pub const DEFAULT_STACK_LIMIT: usize = 4096;

    /// An empty counter with the default stack limit.
    pub fn new() -> Self {
        Rainflow::with_stack_limit(Rainflow::DEFAULT_STACK_LIMIT)
    }

    /// An empty counter keeping at most `limit` (at least 3) reversals.
    pub fn with_stack_limit(limit: usize) -> Self {
        Rainflow {
            points: Vec::new(),
            candidate: None,
            direction: 0,
            stack_limit: limit.max(3),
            truncations: 0,
        }
    }

    /// Times the stack limit cut the residue (0 for any history that stays under it).
    pub fn truncations(&self) -> u64 {
        self.truncations
    }

    /// Reversals currently kept (the residue so far, plus at most one pending extreme).
    pub fn kept_points(&self) -> usize {
        self.points.len() + usize::from(self.candidate.is_some())
    }

    /// Feeds the next value of the history; counted cycles go to `sink`. Non-finite values
    /// are ignored.
    pub fn push(&mut self, x: f64, sink: &mut impl FnMut(Cycle)) {
        if !x.is_finite() {
            return;
        }
        let Some(&last) = self.points.last() else {
            self.points.push(x);
            return;
        };
        match (self.direction, self.candidate) {
            (0, _) => {
                if x != last {
                    self.direction = if x > last { 1 } else { -1 };
                    self.candidate = Some(x);
                }
            }
            (dir, Some(c)) => {
                if (x - c) * dir as f64 >= 0.0 {
                    // Still going the same way (or level): the extreme moves on.
                    self.candidate = Some(x);
                } else {
                    // The candidate was a reversal.
                    self.add_reversal(c, sink);
                    self.direction = -dir;
                    self.candidate = Some(x);
                }
            }
            (_, None) => unreachable!("a direction always has a candidate"),
        }
    }

    /// Ends the history: the last value is a reversal, and the residue is counted as half
    /// cycles (rule 6). The counter is then empty and can start a new history.
    pub fn finish(&mut self, sink: &mut impl FnMut(Cycle)) {
        if let Some(c) = self.candidate.take() {
            self.add_reversal(c, sink);
        }
        for w in self.points.windows(2) {
            sink(half(w[0], w[1]));
        }
        self.points.clear();
        self.direction = 0;
    }

    fn add_reversal(&mut self, x: f64, sink: &mut impl FnMut(Cycle)) {
        self.points.push(x);
        loop {
            let n = self.points.len();
            if n < 3 {
                break;
            }
            let p = &self.points;
            let x_range = (p[n - 1] - p[n - 2]).abs();
            let y_range = (p[n - 2] - p[n - 3]).abs();
            if x_range < y_range {
                break;
            }
            if n == 3 {
                // Y contains S: half cycle, S moves to Y's second point.
                sink(half(p[0], p[1]));
                self.points.remove(0);
            } else {
                sink(Cycle {
                    range: y_range,
                    mean: 0.5 * (p[n - 2] + p[n - 3]),
                    count: 1.0,
                });
                self.points.drain(n - 3..n - 1);
            }
        }
        if self.points.len() > self.stack_limit {
            sink(half(self.points[0], self.points[1]));
            self.points.remove(0);
            self.truncations += 1;
        }
    }
}

fn half(a: f64, b: f64) -> Cycle {
    Cycle {
        range: (b - a).abs(),
        mean: 0.5 * (a + b),
        count: 0.5,
    }
}

/// Counts a whole history at once ([`Rainflow`]), cycles in the order they are counted.
pub fn count_cycles(history: &[f64]) -> Vec<Cycle> {
    let mut out = Vec::new();
    let mut rf = Rainflow::new();
    let mut sink = |c: Cycle| out.push(c);
    for &x in history {
        rf.push(x, &mut sink);
    }
    rf.finish(&mut sink);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_reversals_and_plateaus_are_merged() {
        // 0, 1, 2, 2, 3 (rising, with a plateau), 1, 1, -1: reversals 0, 3, -1.
        let c = count_cycles(&[0.0, 1.0, 2.0, 2.0, 3.0, 1.0, 1.0, -1.0]);
        let ranges: Vec<f64> = c.iter().map(|c| c.range).collect();
        assert_eq!(ranges, vec![3.0, 4.0]);
        assert!(c.iter().all(|c| c.count == 0.5));
    }

    #[test]
    fn a_pulse_train_from_zero_is_one_cycle_per_pulse() {
        let peaks = [3.0, 5.0, 2.0, 2.0, 7.0, 1.0];
        let mut h = vec![0.0];
        for p in peaks {
            h.push(p);
            h.push(0.0);
        }
        let c = count_cycles(&h);
        let total: f64 = c.iter().map(|c| c.count).sum();
        assert_eq!(total, peaks.len() as f64);
        let damage: f64 = c.iter().map(|c| c.count * c.range.powi(3)).sum();
        let expect: f64 = peaks.iter().map(|p| p * p * p).sum();
        assert!((damage - expect).abs() < 1e-12);
    }

    #[test]
    fn the_stack_limit_bounds_memory_of_a_ring_down() {
        // A decaying oscillation keeps every reversal; the limit cuts it.
        let mut rf = Rainflow::with_stack_limit(64);
        let mut n_half = 0;
        for k in 0..10_000 {
            let x = (0.999_f64).powi(k) * if k % 2 == 0 { 1.0 } else { -1.0 };
            rf.push(x, &mut |c: Cycle| {
                if c.count == 0.5 {
                    n_half += 1
                }
            });
            assert!(rf.kept_points() <= 66);
        }
        assert!(rf.truncations() > 0);
        assert!(n_half > 0);
    }
}
