//! Grid points arranged over release speed (x) and friction (y): the layout of the design
//! charts' grid figures and of a comparison's changed cells. Further axes of a sweep are fixed
//! at the value of its first point, and the grid says so.

use serde_json::Value;

use crate::point::{PointRow, MU_KEYS, SPEED_KEYS};

/// Grid points arranged over speed (x) and friction (y).
#[derive(Debug, Clone)]
pub struct Grid {
    /// Distinct speeds (r/min), increasing.
    pub speeds_rpm: Vec<f64>,
    /// Distinct friction coefficients, increasing.
    pub mus: Vec<f64>,
    /// `cells[j * speeds_rpm.len() + i]`: the point at speed `i`, friction `j`, if any.
    pub cells: Vec<Option<PointRow>>,
    /// Every point of the charted slice (the same points as `cells`).
    pub rows: Vec<PointRow>,
    /// "slice at name = value, ..." when the sweep has further axes.
    pub slice: Option<String>,
}

impl Grid {
    /// The point at speed index `i` and friction index `j`.
    pub fn cell(&self, i: usize, j: usize) -> Option<&PointRow> {
        self.cells
            .get(j * self.speeds_rpm.len() + i)
            .and_then(Option::as_ref)
    }
}

/// The finite values of `values`, increasing, with values equal to 1e-9 relative merged.
pub fn distinct_sorted(values: impl IntoIterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-300));
    v
}

fn position(axis: &[f64], x: f64) -> Option<usize> {
    axis.iter()
        .position(|a| (a - x).abs() <= 1e-9 * a.abs().max(x.abs()).max(1e-300))
}

fn format_input(v: &Value) -> String {
    match v {
        Value::Number(n) => n
            .as_f64()
            .map(|x| {
                let s = format!("{x}");
                if s.len() > 10 {
                    format!("{x:.4e}")
                } else {
                    s
                }
            })
            .unwrap_or_else(|| n.to_string()),
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Arranges `rows` on the speed x friction grid. Further axes (inputs that take more than one
/// value) are fixed at the value of the first point (lowest index), and [`Grid::slice`] says
/// so. A missing speed or friction input counts as a single value (0). A point appearing
/// twice (a rerun) is taken from its later line.
pub fn assemble_grid(rows: &[PointRow]) -> Grid {
    let mut first = rows.iter().collect::<Vec<_>>();
    first.sort_by_key(|r| r.index.unwrap_or(u64::MAX));
    let axis_keys: Vec<&str> = SPEED_KEYS.iter().chain(MU_KEYS.iter()).copied().collect();
    let mut fixed: Vec<(String, Value)> = Vec::new();
    let keys: std::collections::BTreeSet<&String> =
        rows.iter().flat_map(|r| r.inputs.keys()).collect();
    for key in keys {
        if axis_keys.contains(&key.as_str()) {
            continue;
        }
        let mut seen: Vec<&Value> = Vec::new();
        for r in rows {
            if let Some(v) = r.inputs.get(key) {
                if !seen.contains(&v) {
                    seen.push(v);
                }
            }
        }
        if seen.len() > 1 {
            if let Some(v) = first.iter().find_map(|r| r.inputs.get(key)) {
                fixed.push((key.clone(), v.clone()));
            }
        }
    }
    let slice: Vec<PointRow> = rows
        .iter()
        .filter(|r| fixed.iter().all(|(k, v)| r.inputs.get(k) == Some(v)))
        .cloned()
        .collect();
    let speed = |r: &PointRow| clamp_value(r.speed_rpm().unwrap_or(0.0));
    let mu = |r: &PointRow| clamp_value(r.mu().unwrap_or(0.0));
    let speeds_rpm = distinct_sorted(slice.iter().map(speed));
    let mus = distinct_sorted(slice.iter().map(mu));
    let mut cells = vec![None; speeds_rpm.len() * mus.len()];
    for r in &slice {
        if let (Some(i), Some(j)) = (position(&speeds_rpm, speed(r)), position(&mus, mu(r))) {
            cells[j * speeds_rpm.len() + i] = Some(r.clone());
        }
    }
    let slice_note = (!fixed.is_empty()).then(|| {
        let parts: Vec<String> = fixed
            .iter()
            .map(|(k, v)| format!("{k} = {}", format_input(v)))
            .collect();
        format!("slice at {}", parts.join(", "))
    });
    Grid {
        speeds_rpm,
        mus,
        cells,
        rows: slice,
        slice: slice_note,
    }
}

/// Largest magnitude drawn: beyond it values are clamped, so spans stay finite.
pub const VALUE_LIMIT: f64 = 1e300;

/// `v` clamped to [`VALUE_LIMIT`] in magnitude (NaN stays NaN).
pub fn clamp_value(v: f64) -> f64 {
    v.clamp(-VALUE_LIMIT, VALUE_LIMIT)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::point::PointStatus;

    #[test]
    fn grid_takes_first_slice_of_a_third_axis() {
        let row = |i: u64, s: f64, m: f64, c: f64| PointRow {
            key: format!("k{i}"),
            index: Some(i),
            inputs: [
                ("speed_rpm".to_string(), Value::from(s)),
                ("mu".to_string(), Value::from(m)),
                ("clearance_m".to_string(), Value::from(c)),
            ]
            .into_iter()
            .collect(),
            status: PointStatus::Failed,
            class: None,
            max_contact_force_n: None,
            peak_heat_power_w: None,
            peak_temperature_k: None,
            peak_contact_pressure_pa: None,
            static_safety_factor: None,
            drops_to_failure: None,
            whirl_stop_turns: None,
            error: None,
            duration_s: None,
            model_version: None,
        };
        let rows = vec![
            row(3, 1000.0, 0.1, 2e-4),
            row(0, 1000.0, 0.1, 1e-4),
            row(1, 2000.0, 0.1, 1e-4),
            row(2, 2000.0, 0.2, 1e-4),
        ];
        let g = assemble_grid(&rows);
        assert_eq!(g.speeds_rpm, vec![1000.0, 2000.0]);
        assert_eq!(g.mus, vec![0.1, 0.2]);
        assert_eq!(g.rows.len(), 3);
        assert!(g.cell(0, 1).is_none());
        assert_eq!(g.cell(1, 1).unwrap().key, "k2");
        assert_eq!(g.slice.as_deref(), Some("slice at clearance_m = 0.0001"));
    }
}
