//! Mechanical energy for the energy audit: kinetic, gravitational and elastic (the Hertz
//! potential of eq. 7's spring for each active contact).

use super::state::{ix, Mode, N};
use super::{hertz, DropSystem};

impl DropSystem {
    /// Mechanical energy (J): kinetic, gravitational (zero at y = 0) and the elastic energy
    /// of the contacts active in `mode`.
    pub fn mechanical_energy(&self, y: &[f64; N], mode: Mode) -> f64 {
        let (mut vcx, mut vcy, mut yc) = (y[ix::VXR], y[ix::VYR], y[ix::YR]);
        if self.e != 0.0 {
            let (sp, cp) = (y[ix::TR] + self.phase).sin_cos();
            vcx -= self.e * y[ix::WR] * sp;
            vcy += self.e * y[ix::WR] * cp;
            yc += self.e * sp;
        }
        let ke_r =
            0.5 * self.m_r * (vcx * vcx + vcy * vcy) + 0.5 * self.j_r * y[ix::WR] * y[ix::WR];
        let ke_b = 0.5 * self.m_b * (y[ix::VXB].powi(2) + y[ix::VYB].powi(2))
            + 0.5 * self.j_b * y[ix::WB].powi(2);
        let pe = self.g * (self.m_r * yc + self.m_b * y[ix::YB]);
        let mut el = 0.0;
        if let Some(ss) = &self.series {
            if mode.contact {
                let dist = (y[ix::XR].powi(2) + y[ix::YR].powi(2)).sqrt();
                el += ss.energy_j(&ss.split(dist - self.s));
            }
            return ke_r + ke_b + pe + el;
        }
        if mode.contact {
            let dist = ((y[ix::XR] - y[ix::XB]).powi(2) + (y[ix::YR] - y[ix::YB]).powi(2)).sqrt();
            el += hertz::elastic_energy(self.k1, self.e1, dist - self.s);
        }
        if mode.support {
            let r = (y[ix::XB].powi(2) + y[ix::YB].powi(2)).sqrt();
            el += hertz::elastic_energy(self.k2, self.e2, r);
        }
        ke_r + ke_b + pe + el
    }
}
