//! Ad-hoc diagnostic: accepted steps of a 1 s drop per 50 ms window and per mode (free,
//! sticking, slipping), to see where a stepper spends its steps.
//! `cargo run --release -p whirlmap-core --example steps -- [rtol=1e-4] [ros=true]
//! [hyb=true] [ndf=true] [bdf=true] [gap=true] [radial=true] [race=1000] [mu=0.1] [rpm=8000]
//! [segs=0.1]`. With `segs=T` it also lists the stretches of one mode (contact, the race on
//! its balls, slip) that start before `T` seconds, with their steps and computed force-model
//! evaluations: the touchdown's impacts, hops and race bounces one by one. The drop's own
//! feature monitor runs after this observer, so the evaluations of a step's monitor samples
//! and peak searches are counted with the next step (at a stretch's start, in the stretch
//! before).
use std::convert::Infallible;
use std::ops::ControlFlow;
use whirlmap_core::ode::{Observer, StepView};
use whirlmap_core::*;
struct Rec(
    /// Per accepted step: start, end, contact, slip (0 sticking, else its sign), computed
    /// model evaluations so far (up to the step's monitor, which runs after this observer),
    /// the race on its balls.
    Vec<(f64, f64, bool, i32, u64, bool)>,
    model::ModelEvals,
    Vec<(f64, f64, f64)>,
    /// Accepted multistep steps per order (index 0: one-step methods' steps).
    [u64; 6],
);
impl Observer<model::DropSystem, { model::N }> for Rec {
    type Halt = Infallible;
    fn on_step(
        &mut self,
        sys: &model::DropSystem,
        s: &StepView<'_, { model::N }>,
    ) -> ControlFlow<Infallible> {
        let m = sys.mode;
        let sl = match m.slip {
            model::Slip::Sticking => 0,
            model::Slip::Slipping(x) => x as i32,
        };
        self.0.push((
            s.dense.t0(),
            s.dense.t1(),
            m.contact,
            sl,
            sys.model_evals().computed,
            m.support,
        ));
        if !m.contact {
            use whirlmap_core::ode::OdeSystem;
            let cap = sys.max_step_at(s.dense.t0(), &s.dense.y0());
            self.2
                .push((s.dense.t0(), s.dense.t1() - s.dense.t0(), cap));
        }
        self.1 = sys.model_evals();
        self.3[s.dense.multistep_order().unwrap_or(0)] += 1;
        ControlFlow::Continue(())
    }
}
fn main() {
    let mut s = Scene::paper();
    let mut segs_until_s = 0.0;
    for a in std::env::args().skip(1) {
        let (k, v) = a.split_once('=').unwrap();
        match k {
            "rtol" => s.solver.rtol = v.parse().unwrap(),
            "radial" => {
                if v == "true" {
                    s.support_damper = SupportDamper::RadialOnly
                }
            }
            "gap" => s.solver.free_flight_gap_bound = v.parse().unwrap(),
            "ros" => {
                if v == "true" {
                    s.solver.method = scene::Method::Ros34pw2
                }
            }
            "bdf" => {
                if v == "true" {
                    s.solver.method = scene::Method::Bdf
                }
            }
            "hyb" => {
                if v == "true" {
                    s.solver.method = scene::Method::Rodas4Bdf
                }
            }
            "ndf" => {
                if v == "true" {
                    s.solver.method = scene::Method::Rodas4Ndf
                }
            }
            "race" => s.solver.race_atol_scale = v.parse().unwrap(),
            "mu" => s.mu_dynamic = v.parse().unwrap(),
            "rpm" => s.speed_rpm = v.parse().unwrap(),
            "segs" => segs_until_s = v.parse().unwrap(),
            _ => panic!("{k}"),
        }
    }
    let mut rec = Rec(Vec::new(), Default::default(), Vec::new(), [0; 6]);
    let r = simulate_observed(
        &s,
        &DropOptions {
            duration_s: 1.0,
            ..Default::default()
        },
        &mut rec,
    )
    .unwrap();
    println!("{:?} stop: {:?}", r.stats, r.stop_reason);
    println!("model evaluations: {:?}", rec.1);
    println!(
        "steps: one-step {}, multistep at orders 1-5 {:?}",
        rec.3[0],
        &rec.3[1..]
    );
    let mut w = [[0usize; 5]; 20];
    let mut prev = 0u64;
    for &(t0, _t1, c, sl, ev, _) in &rec.0 {
        let b = ((t0 / 0.05) as usize).min(19);
        let k = if !c {
            0
        } else if sl == 0 {
            1
        } else {
            2
        };
        w[b][k] += 1;
        w[b][3] += 1;
        w[b][4] += (ev - prev) as usize;
        prev = ev;
    }
    if segs_until_s > 0.0 {
        println!("start (ms)  length (ms)  contact  on balls  slip  steps  evals");
        let (mut i, mut before) = (0, 0u64);
        while i < rec.0.len() && rec.0[i].0 < segs_until_s {
            let (t0, _, c, sl, _, sup) = rec.0[i];
            let mut j = i;
            while j + 1 < rec.0.len()
                && (rec.0[j + 1].2, rec.0[j + 1].3, rec.0[j + 1].5) == (c, sl, sup)
            {
                j += 1;
            }
            let (t1, ev) = (rec.0[j].1, rec.0[j].4);
            println!(
                "{:>10.3} {:>12.3} {:>8} {:>9} {:>5} {:>6} {:>6}",
                t0 * 1e3,
                (t1 - t0) * 1e3,
                c,
                sup,
                sl,
                j - i + 1,
                ev - before
            );
            before = ev;
            i = j + 1;
        }
    }
    let capped = rec.2.iter().filter(|r| r.1 >= 0.999 * r.2).count();
    let hmean = rec.2.iter().map(|r| r.1).sum::<f64>() / rec.2.len().max(1) as f64;
    println!(
        "free steps {}, at the step cap {}, mean h {:.3e} s",
        rec.2.len(),
        capped,
        hmean
    );
    println!("window  free  stick  slip  total  evals/step");
    for (i, r) in w.iter().enumerate() {
        println!(
            "{:>4} ms {:>6} {:>6} {:>6} {:>6} {:>6.2}",
            i * 50,
            r[0],
            r[1],
            r[2],
            r[3],
            r[4] as f64 / r[3].max(1) as f64
        );
    }
}
