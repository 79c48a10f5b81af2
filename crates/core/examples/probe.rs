//! Ad-hoc probe: `cargo run --release -p whirlmap-core --example probe -- RPM MU DUR [key=val]`.
use whirlmap_core::*;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let mut s = Scene::paper();
    s.speed_rpm = a.get(1).map_or(8000.0, |x| x.parse().unwrap());
    s.mu_dynamic = a.get(2).map_or(0.1, |x| x.parse().unwrap());
    let dur = a.get(3).map_or(1.0, |x| x.parse().unwrap());
    if let Some(r) = a.get(4) {
        s.solver.rtol = r.parse().unwrap();
    }
    let t = std::time::Instant::now();
    let r = simulate(
        &s,
        &DropOptions {
            duration_s: dur,
            ..Default::default()
        },
    );
    let el = t.elapsed();
    match r {
        Ok(r) => println!(
            "{:#?}\n{:?}\n{:?}\nstop {:?} t_end {} wall {:?}",
            r.features, r.energy, r.stats, r.stop_reason, r.end_time_s, el
        ),
        Err(e) => println!("error {e} after {el:?}"),
    }
}
