//! # whirlmap-core: the touchdown-bearing drop model and its integrator
//!
//! A rotor falls out of its active magnetic bearings onto a touchdown ball bearing. This
//! crate simulates that drop as in the paper *A performance analysis model with thermodynamic
//! and superficial effects of the touchdown bearings in AMB systems* (eqs. 1-13 and 17), with
//! the points the paper leaves open resolved as docs/model.md says. No threads,
//! no files, no plotting: a sweep crate fans it out and draws the charts.
//!
//! ## State
//! Fifteen numbers (see [`model::ix`]): rotor geometric centre and angle `(x_r, y_r,
//! theta_r)`, race centre and angle `(x_b, y_b, theta_b)`, their six rates, and three energy
//! accumulators (friction heat, damper loss, drag work) integrated alongside so the energy
//! audit sees the same error control.
//!
//! ## Equations
//! - Rotor, eqs. 1-3, with unbalance solved exactly from Lagrange's equations
//!   ([`model::DropSystem`]); race, eqs. 4-6, with Newton's third law at the contact.
//! - Rotor-race contact, eq. 7 (`k1 = 1.988e9 N/m^(10/9)`, `c1 = 1000 N s/m`), and the race on
//!   a lumped isotropic ball support (`k2 = 7.811e9 N/m^1.5`, `c2 = 750 N s/m`); a damper never
//!   pulls ([`model::hertz`]).
//! - Coulomb friction, eq. 8, with the stick/slip switch of eqs. 9-10 as located events
//!   ([`model::friction`]); a regularised law is an option.
//! - Palmgren drag on the race, eqs. 11-13 ([`model::drag`]).
//! - Heat: `H_s = F_t v_rel` (eq. 17) and the bearing drag power `M |omega_b|`.
//! - Optional thermal model ([`thermal`], eqs. 14-31): the bearing heat split into `H_i` and
//!   `H_o`, the seven-node heat network, expansion and the thermally induced load fed back
//!   into the drag torque, coupled to the dynamics by macro steps. A scene switches it on
//!   with `thermal`; without it nothing thermal is computed.
//!
//! ## Integrator
//! [`ode`]: by default (the `standard` fidelity) RODAS4 then BDF ([`ode::Rodas4Bdf`]): the
//! Rosenbrock method RODAS4 on the model's full Jacobian after every mode switch, and the
//! variable-order BDF once the contact has run smoothly (the `draft` fidelity's too); RODAS4
//! alone (the `draft` fidelity's until 2026-11-29), the BDF alone, the Rosenbrock-W method
//! ROS34PW2, Rodas5P, RADAU5, Dormand-Prince 5(4) (the `reference` fidelity) and DOP853, all
//! with dense output; contact onset and loss, support release, slip reversal and stick
//! break-away are guard crossings located on the interpolant; the step is bounded in free
//! flight; force and power peaks are located on the interpolant by the [`monitor::Monitor`]
//! observer. Errors are typed and carry the time ([`SolveError`]).
//!
//! ## Classification
//! [`classify`](mod@classify): the orbit class is decided on the final window of the run
//! from streamed features; a run that has not settled is extended until it has (up to a
//! cap).
//!
//! ## One drop
//! ```
//! use whirlmap_core::{simulate, DropOptions, Scene};
//! let mut scene = Scene::paper();
//! scene.speed_rpm = 8000.0;
//! scene.mu_dynamic = 0.1;
//! let report = simulate(&scene, &DropOptions { duration_s: 0.02, ..Default::default() }).unwrap();
//! assert!(report.features.first_contact_force_n > 0.0);
//! // The audit closes to integration error, well inside the tolerance (rtol 1e-4).
//! assert!(report.energy.residual_rel < scene.solver.rtol);
//! ```
#![warn(missing_docs)]
// Lints allowed on purpose: integrator coefficients are copied digit for digit from their
// papers (Dormand-Prince, Hairer-Wanner, Rang-Angermann) so they can be checked against the
// source; `!(x > 0.0)` is how validation rejects NaN with the bad values; index loops over
// small fixed-size matrices mirror the equations they implement.
#![allow(
    clippy::excessive_precision,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::needless_range_loop
)]

pub mod bearing;
pub mod classify;
pub mod drop;
pub mod error;
pub mod fidelity;
pub mod json;
pub mod model;
pub mod monitor;
pub mod ode;
pub mod orbit;
pub mod scene;
pub mod schema;
pub mod thermal;

pub use classify::{classify, ClassifyParams, OrbitClass, Reason, Verdict};
pub use drop::{
    simulate, simulate_observed, DropInputs, DropOptions, DropReport, EnergyAudit, StopReason,
    MODEL_VERSION,
};
pub use error::{InvalidParameter, SolveError};
pub use fidelity::Fidelity;
pub use monitor::{Features, Window, WindowStats};
pub use scene::{FrictionLaw, Method, Scene, SolverSettings, SupportDamper};
pub use thermal::{ThermalParams, ThermalReport};
