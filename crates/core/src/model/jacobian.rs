//! The stiff part of the model's Jacobian for the linearly implicit steppers (ROS34PW2,
//! RODAS4): the derivatives of eq. 7's two Hertz contacts and of the friction that follows
//! them (eq. 8), over the translations, their rates and the two spins; and the rows of the
//! accumulators (energy integrals, angles) over the same components.

use super::friction::FrictionSlopes;
use super::state::{ix, N};
use super::{drag, hertz, DropSystem};
use crate::ode::StiffJacobian;
use nalgebra::{Matrix2, Vector2};

impl DropSystem {
    /// The stiff part of the Jacobian for the linearly implicit stepper: the two Hertz
    /// contacts' normal forces (eq. 7, spring and damper, with the turning of the contact
    /// normal), the friction that follows them (eq. 8; the regularised law's slope in the
    /// slip velocity too), over the translations, their rates and the two spins. Left out,
    /// because they are not stiff: gravity, the unbalance terms, Palmgren drag, and the
    /// sticking constraint's dependence on the state. For RODAS4, which keeps its order only
    /// with the exact Jacobian, the matrix also holds the drag's slopes (eqs. 11-13) and the
    /// sticking constraint's (eq. 9), and its quadrature rows: the energy integrals' powers
    /// (eq. 17's H_s, the dampers' power, the drag's M |omega_b|) and the two angles
    /// (theta' = omega). Only the unbalance terms are left out then.
    #[inline]
    pub(super) fn fill_stiff_jacobian_at(&self, y: &[f64; N], sj: &mut StiffJacobian) {
        use ix::*;
        // Blocks of the stiff set: rotor position 0..2, race position 2..4, rotor velocity
        // 4..6, race velocity 6..8, then the rotor's (8) and the race's (9) spin.
        const QR: usize = 0;
        const QB: usize = 2;
        const VR: usize = 4;
        const VB: usize = 6;
        const SR: usize = 8;
        const SB: usize = 9;
        sj.reset_over(&[XR, YR, XB, YB, VXR, VYR, VXB, VYB, WR, WB]);
        // The four positions' rows are exactly q' = v (eqs. 1-6): the stepper eliminates them.
        sj.kinematic = 4;
        // The energy integrals' rows (their powers over the same components), then the two
        // angles' (theta' = omega; without unbalance no force reads an angle).
        const FRIC: usize = 0;
        const DAMP: usize = 1;
        const DRAG: usize = 2;
        sj.quad_idx[..5].copy_from_slice(&[E_FRIC, E_DAMP, E_DRAG, TR, TB]);
        sj.quad[(3, SR)] = 1.0;
        sj.quad[(4, SB)] = 1.0;
        // The gradient of the load the drag sees (the support force) over the rotor's and
        // the race's positions and velocities.
        let mut dload = [Vector2::zeros(); 4];
        let j = &mut sj.jac;
        j.fixed_view_mut::<4, 4>(QR, VR).fill_with_identity();
        let f = self.forces(y);
        // The drag's torque and slopes, once, for both places that read them (exact only).
        let drag = if self.exact_jacobian {
            self.drag_slopes(y, &f)
        } else {
            None
        };
        // t = R n with R the quarter turn.
        let quarter = Matrix2::new(0.0, -1.0, 1.0, 0.0);
        if self.mode.contact && f.dist_m > 0.0 {
            let (n, t, dist) = (f.n, f.t, f.dist_m);
            let w = Vector2::new(y[VXR] - y[VXB], y[VYR] - y[VYB]);
            // P = I - n n^T: how n turns with d; R P: how t turns.
            let p = Matrix2::identity() - n * n.transpose();
            let rp = quarter * p;
            let pw = p * w;
            // kd: dF_n/dd along n; c: the damper; dc: its slope in the penetration.
            let (kd, c, dc) = match &self.series {
                Some(ss) => {
                    // Series springs: dF/dd = F / (a/e1 + b/e2); the split damper's weight
                    // w = (a/e1) / (a/e1 + b/e2) moves with d too (its slope times delta_dot
                    // joins the stiffness).
                    let sp = ss.split(f.delta_m);
                    let (pp, q) = (ss.inv_e1(), ss.inv_e2());
                    let (a, b, fa) = (sp.delta_m, sp.support_m, sp.force_n.abs());
                    let denom = a * pp + b * q;
                    let wc = sp.w_contact;
                    let c = self.c1 * wc * wc + self.c2 * (1.0 - wc) * (1.0 - wc);
                    let (kd, dc) = if denom > 0.0 && fa > 0.0 {
                        let k = fa / denom;
                        let dw = pp * q * a * b * (pp - q) * k / (fa * denom * denom);
                        let dc = 2.0 * (self.c1 * wc - self.c2 * (1.0 - wc)) * dw;
                        (k + dc * f.delta_dot_m_s, dc)
                    } else {
                        (0.0, 0.0)
                    };
                    (kd, c, dc)
                }
                None => {
                    let d = f.delta_m.max(0.0);
                    // `f.contact_pow` is `signed_pow(delta, e1)`, and `d` is `delta` here.
                    let kd = if d > 0.0 {
                        self.k1 * self.e1 * f.contact_pow / d
                    } else {
                        0.0
                    };
                    (kd, self.c1, 0.0)
                }
            };
            let (fnn, ft) = (f.normal_n, f.friction_n);
            // Gradients of F_n (eq. 7) over d = p_r - p_b and w = v_r - v_b.
            let dfn_dd = kd * n + (c / dist) * pw;
            let dfn_dw = c * n;
            // Friction: d F_t over d, w and the two spins.
            let (mut dft_dd, mut dft_dw, mut dft_dwr, mut dft_dwb) =
                (Vector2::zeros(), Vector2::zeros(), 0.0, 0.0);
            // While sticking (exact Jacobian only): the constraint's friction also follows the
            // race's own position and velocity, through the support force.
            let mut sticking: Option<StickingSlopes> = None;
            match self.friction.slopes(self.mode.slip, fnn, f.v_rel_m_s) {
                FrictionSlopes::Smooth {
                    per_normal,
                    per_slip_velocity,
                } => {
                    // v_rel depends on d through the turning tangent: (R P)^T w / |d|.
                    let dv_dd = rp.transpose() * w / dist;
                    dft_dd = per_normal * dfn_dd + per_slip_velocity * dv_dd;
                    dft_dw = per_normal * dfn_dw + per_slip_velocity * t;
                    dft_dwr = per_slip_velocity * self.r_r;
                    dft_dwb = -per_slip_velocity * self.r_b;
                }
                FrictionSlopes::Proportional { per_normal } => {
                    dft_dd = per_normal * dfn_dd;
                    dft_dw = per_normal * dfn_dw;
                }
                FrictionSlopes::Constraint => {
                    if self.exact_jacobian && self.series.is_none() {
                        let g = self.sticking_slopes(y, &f, drag.as_ref(), w, rp, p);
                        (dft_dd, dft_dw, dft_dwb) = (g.dd, g.dw, g.dwb);
                        sticking = Some(g);
                    }
                }
            }
            // Force on the race fc = F_n n + F_t t (the rotor gets -fc), over d and w.
            let dfc_dd = n * dfn_dd.transpose()
                + (fnn / dist) * p
                + t * dft_dd.transpose()
                + (ft / dist) * rp;
            let dfc_dw = n * dfn_dw.transpose() + t * dft_dw.transpose();
            let (ir, ib) = (1.0 / self.m_r, 1.0 / self.m_b);
            let mut block = |row: usize, col: usize, m: Matrix2<f64>| {
                let mut v = j.fixed_view_mut::<2, 2>(row, col);
                v += m;
            };
            // Rotor rows: -fc / m_r, with d = p_r - p_b and w = v_r - v_b.
            block(VR, QR, -dfc_dd * ir);
            block(VR, VR, -dfc_dw * ir);
            let race = self.series.is_none();
            if self.exact_jacobian {
                // Quadrature rows: eq. 17's H_s = F_t v_rel and the contact damper's power
                // c delta_dot^2, over d, w and the spins (the race's columns with the other sign).
                let (v_rel, dd) = (f.v_rel_m_s, f.delta_dot_m_s);
                let dhs_dd = v_rel * dft_dd + ft * (rp.transpose() * w / dist);
                let dhs_dw = v_rel * dft_dw + ft * t;
                let dpd_dd = (2.0 * c * dd / dist) * pw + (dd * dd * dc) * n;
                let dpd_dw = (2.0 * c * dd) * n;
                {
                    let mut row = |r: usize, col: usize, v: Vector2<f64>| {
                        let mut seg = sj.quad.fixed_view_mut::<1, 2>(r, col);
                        seg += v.transpose();
                    };
                    row(FRIC, QR, dhs_dd);
                    row(FRIC, VR, dhs_dw);
                    row(DAMP, QR, dpd_dd);
                    row(DAMP, VR, dpd_dw);
                    if race {
                        row(FRIC, QB, -dhs_dd);
                        row(FRIC, VB, -dhs_dw);
                        row(DAMP, QB, -dpd_dd);
                        row(DAMP, VB, -dpd_dw);
                    }
                }
                sj.quad[(FRIC, SR)] += v_rel * dft_dwr + ft * self.r_r;
                sj.quad[(FRIC, SB)] += v_rel * dft_dwb - ft * self.r_b;
                if let Some(g) = &sticking {
                    let mut seg = sj.quad.fixed_view_mut::<1, 2>(FRIC, QB);
                    seg += v_rel * g.qb.transpose();
                    let mut seg = sj.quad.fixed_view_mut::<1, 2>(FRIC, VB);
                    seg += v_rel * g.vb.transpose();
                }
                if !race && fnn > 0.0 {
                    // The quasi-static race's support carries the contact force.
                    dload[0] = dfn_dd;
                    dload[1] = dfn_dw;
                }
            }
            if race {
                block(VR, QB, dfc_dd * ir);
                block(VR, VB, dfc_dw * ir);
                block(VB, QR, dfc_dd * ib);
                block(VB, QB, -dfc_dd * ib);
                block(VB, VR, dfc_dw * ib);
                block(VB, VB, -dfc_dw * ib);
            }
            let mut column = |row: usize, col: usize, v: Vector2<f64>| {
                let mut c = j.fixed_view_mut::<2, 1>(row, col);
                c += v;
            };
            column(VR, SR, -t * (dft_dwr * ir));
            column(VR, SB, -t * (dft_dwb * ir));
            if race {
                column(VB, SR, t * (dft_dwr * ib));
                column(VB, SB, t * (dft_dwb * ib));
            }
            // Spin rows: omega_r' = -F_t r_r / J_r, omega_b' = F_t R_b / J_b.
            for (row, scale) in [(SR, -self.r_r / self.j_r), (SB, self.r_b / self.j_b)] {
                let mut r = j.fixed_view_mut::<1, 2>(row, QR);
                r += scale * dft_dd.transpose();
                let mut r = j.fixed_view_mut::<1, 2>(row, VR);
                r += scale * dft_dw.transpose();
                if race {
                    let mut r = j.fixed_view_mut::<1, 2>(row, QB);
                    r -= scale * dft_dd.transpose();
                    let mut r = j.fixed_view_mut::<1, 2>(row, VB);
                    r -= scale * dft_dw.transpose();
                }
                j[(row, SR)] += scale * dft_dwr;
                j[(row, SB)] += scale * dft_dwb;
            }
            if let Some(g) = &sticking {
                // F_t's slopes in the race's position and velocity themselves: F_t t acts on
                // the rotor (-) and the race (+), its torque on both spins.
                for (col, v) in [(QB, g.qb), (VB, g.vb)] {
                    let mut m = j.fixed_view_mut::<2, 2>(VR, col);
                    m -= t * v.transpose() * ir;
                    let mut m = j.fixed_view_mut::<2, 2>(VB, col);
                    m += t * v.transpose() * ib;
                    let mut r = j.fixed_view_mut::<1, 2>(SR, col);
                    r -= (self.r_r / self.j_r) * v.transpose();
                    let mut r = j.fixed_view_mut::<1, 2>(SB, col);
                    r += (self.r_b / self.j_b) * v.transpose();
                }
            }
        }
        if self.series.is_none() && self.mode.support {
            if let Some(SupportGeometry {
                r,
                nb,
                vn,
                pb,
                pv,
                kd,
            }) = self.support_geometry(y)
            {
                let fs = f.support_n;
                // The support's force -F_s nb (eq. 7, radial) and its radial damper, over the
                // race position and velocity; then the tangential damper -c2_t (v - nb (nb.v))
                // and its turning with nb.
                let dp = nb * (kd * nb + (self.c2 / r) * pv).transpose() + (fs / r) * pb;
                let ib = 1.0 / self.m_b;
                let tangential_dq = self.c2_t * (pb * vn + nb * pv.transpose()) / (r * self.m_b);
                let mut q = j.fixed_view_mut::<2, 2>(VB, QB);
                q -= dp * ib;
                q += tangential_dq;
                let mut v = j.fixed_view_mut::<2, 2>(VB, VB);
                v -= (self.c2 * ib) * nb * nb.transpose();
                v -= (self.c2_t * ib) * pb;
                if self.exact_jacobian {
                    // The support dampers' power c2 r_dot^2 + c2_t |P v|^2.
                    let mut seg = sj.quad.fixed_view_mut::<1, 2>(DAMP, QB);
                    seg += ((2.0 * vn * (self.c2 - self.c2_t) / r) * pv).transpose();
                    let mut seg = sj.quad.fixed_view_mut::<1, 2>(DAMP, VB);
                    seg += (2.0 * self.c2 * vn * nb + 2.0 * self.c2_t * pv).transpose();
                    dload[2] = kd * nb + (self.c2 / r) * pv;
                    dload[3] = self.c2 * nb;
                }
            }
        }
        if let Some(DragSlopes {
            m,
            dm_dw,
            dm_dload,
            dir,
            ddir,
        }) = drag
        {
            // The drag's power M |omega_b| (regularised: M dir(omega_b) omega_b), over the
            // race's spin and, through the Palmgren load, the support force's state.
            let wb = y[WB];
            sj.quad[(DRAG, SB)] += dm_dw * dir * wb + m * (ddir * wb + dir);
            let scale = dm_dload * dir * wb;
            for (g, col) in dload.iter().zip([QR, VR, QB, VB]) {
                let mut seg = sj.quad.fixed_view_mut::<1, 2>(DRAG, col);
                seg += (scale * g).transpose();
            }
            // The drag torque -M dir(omega_b) on the race's spin (eq. 6), which the W-method's
            // matrix leaves out as not stiff.
            j[(SB, SB)] -= (dm_dw * dir + m * ddir) / self.j_b;
            let per_load = dm_dload * dir / self.j_b;
            for (g, col) in dload.iter().zip([QR, VR, QB, VB]) {
                let mut seg = j.fixed_view_mut::<1, 2>(SB, col);
                seg -= (per_load * g).transpose();
            }
        }
        // The accumulators' rows, for the method that needs them.
        sj.quad_len = if self.exact_jacobian { 5 } else { 0 };
    }

    /// The Palmgren drag's torque and slopes at `y` (eqs. 11-13): `None` without drag.
    fn drag_slopes(&self, y: &[f64; N], f: &super::forces::Forces) -> Option<DragSlopes> {
        let p = self.drag.as_ref()?;
        let wb = y[ix::WB];
        let load = f.support_n + self.thermal_load_n;
        let (m, dm_dw, dm_dload) = p.torque_and_slopes_from(f.drag_powers, wb, load);
        let (dir, ddir) = drag::direction_and_slope(wb, self.omega_eps);
        Some(DragSlopes {
            m,
            dm_dw,
            dm_dload,
            dir,
            ddir,
        })
    }

    /// The ball support's geometry at `y` (eq. 7 with e = 3/2): `None` with the race at the
    /// housing's centre, where its direction is undefined.
    #[inline]
    fn support_geometry(&self, y: &[f64; N]) -> Option<SupportGeometry> {
        use ix::*;
        let b = Vector2::new(y[XB], y[YB]);
        let r = b.norm();
        if r <= 0.0 {
            return None;
        }
        let nb = b / r;
        let vb = Vector2::new(y[VXB], y[VYB]);
        let vn = vb.dot(&nb);
        let pb = Matrix2::identity() - nb * nb.transpose();
        Some(SupportGeometry {
            r,
            nb,
            vn,
            pb,
            pv: pb * vb,
            kd: self.k2 * self.e2 * hertz::signed_pow(r, self.e2) / r,
        })
    }

    /// The slopes of the sticking constraint's friction (eq. 9 held: `v_rel' = 0`). The slip
    /// acceleration is affine in `F_t`, `s(F_t) = s0 - K F_t` with the constant
    /// `K = 1/m_r + 1/m_b + r_r^2/J_r + r_b^2/J_b` (without unbalance), so `F_t = s0 / K` and
    /// its slopes are those of `s0 = -(S . t)/m_b - v_t delta_dot/|d| - M_b r_b/J_b`, the slip
    /// acceleration without friction: `S` the support force on the race (eq. 7 and its
    /// dampers), `M_b` the signed drag torque (eqs. 11-13).
    fn sticking_slopes(
        &self,
        y: &[f64; N],
        f: &super::forces::Forces,
        drag: Option<&DragSlopes>,
        w: Vector2<f64>,
        rp: Matrix2<f64>,
        p: Matrix2<f64>,
    ) -> StickingSlopes {
        let k = 1.0 / self.m_r
            + 1.0 / self.m_b
            + self.r_r * self.r_r / self.j_r
            + self.r_b * self.r_b / self.j_b;
        let (n, t, dist) = (f.n, f.t, f.dist_m);
        let (v_t, dd) = (w.dot(&t), f.delta_dot_m_s);
        // The support force S and its slopes in the race's position and velocity.
        let (mut s_vec, mut ds_db, mut ds_dvb) =
            (Vector2::zeros(), Matrix2::zeros(), Matrix2::zeros());
        let (mut dfs_db, mut dfs_dvb) = (Vector2::zeros(), Vector2::zeros());
        if let (true, Some(g)) = (self.mode.support, self.support_geometry(y)) {
            let SupportGeometry {
                r,
                nb,
                vn,
                pb,
                pv,
                kd,
            } = g;
            let fs = f.support_n;
            s_vec = -fs * nb - self.c2_t * pv;
            dfs_db = kd * nb + (self.c2 / r) * pv;
            dfs_dvb = self.c2 * nb;
            ds_db = -(nb * dfs_db.transpose() + (fs / r) * pb)
                + (self.c2_t / r) * (vn * pb + nb * pv.transpose());
            ds_dvb = -(self.c2 * nb * nb.transpose()) - self.c2_t * pb;
        }
        // -(S . t)/m_b: t turns with d; S moves with the race.
        let mut dd_grad = -(rp.transpose() * s_vec) / (dist * self.m_b);
        let mut qb = -(ds_db.transpose() * t) / self.m_b;
        let mut vb = -(ds_dvb.transpose() * t) / self.m_b;
        // -v_t delta_dot / |d|.
        let dw = -(dd * t + v_t * n) / dist;
        dd_grad += -(dd * (rp.transpose() * w) + v_t * (p * w)) / (dist * dist)
            + (v_t * dd / (dist * dist)) * n;
        // -M_b r_b / J_b with M_b = -M dir(omega_b).
        let mut dwb = 0.0;
        if let Some(&DragSlopes {
            m,
            dm_dw,
            dm_dload,
            dir,
            ddir,
        }) = drag
        {
            let c = self.r_b / self.j_b;
            dwb = c * (dm_dw * dir + m * ddir);
            qb += (c * dm_dload * dir) * dfs_db;
            vb += (c * dm_dload * dir) * dfs_dvb;
        }
        // The race's relative position and velocity enter with d = p_r - p_b, w = v_r - v_b:
        // the blocks give the race's columns the opposite sign of these.
        StickingSlopes {
            dd: dd_grad / k,
            dw: dw / k,
            dwb: dwb / k,
            qb: qb / k,
            vb: vb / k,
        }
    }
}

/// The sticking constraint's friction slopes ([`DropSystem`]'s `sticking_slopes`): over the
/// relative position `d` and velocity `w` (the race's columns take them with the other sign),
/// the race's spin, and the race's own position and velocity (through the support force).
struct StickingSlopes {
    dd: Vector2<f64>,
    dw: Vector2<f64>,
    dwb: f64,
    qb: Vector2<f64>,
    vb: Vector2<f64>,
}

/// The ball support's geometry at one state: the race centre's distance `r` from the
/// housing's centre (m), its direction `nb`, the race's radial speed `vn` (m/s), the projector
/// `pb` across `nb`, the race's velocity across it `pv` (m/s), and the Hertz law's slope `kd`
/// (N/m).
struct SupportGeometry {
    r: f64,
    nb: Vector2<f64>,
    vn: f64,
    pb: Matrix2<f64>,
    pv: Vector2<f64>,
    kd: f64,
}

/// The Palmgren drag at one state: the torque's magnitude `m` (N m), its slopes in the race's
/// spin `dm_dw` (N m s) and in the load `dm_dload` (m), and the direction factor `dir` with its
/// slope `ddir` (s/rad).
#[derive(Clone, Copy)]
struct DragSlopes {
    m: f64,
    dm_dw: f64,
    dm_dload: f64,
    dir: f64,
    ddir: f64,
}
