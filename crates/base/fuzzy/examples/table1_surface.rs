//! Builds the crawler trajectory-tracking fuzzy controller of the
//! electric-shovel paper's §4.3 (Mamdani & Assilian 1975 inference) with
//! autoshovel-fuzzy: e = lateral deviation (m) ∈ [−0.45, 0.45], ec = its
//! rate ∈ [−30, 30], u = track motor speed difference (rpm) ∈ [−2700, 2700],
//! seven triangles NB … PB each and the 7 × 7 Table 1 (rows ec, columns e).
//! Prints u at a few points and a coarse control surface, and asserts the
//! odd symmetry and the sign of the response.
//!
//! Run: `cargo run -p autoshovel-fuzzy --example table1_surface`

use autoshovel_fuzzy::presets::shovel_table1::{self, TERMS};
use autoshovel_fuzzy::{FuzzyError, MamdaniSystem};

fn build() -> Result<MamdaniSystem, FuzzyError> {
    shovel_table1::system()
}

/// Rounding noise around 0 (e.g. −2e−14) printed as 0, not "−0".
fn tidy(v: f64) -> f64 {
    if v.abs() < 1e-6 {
        0.0
    } else {
        v
    }
}

fn main() -> Result<(), FuzzyError> {
    let sys = build()?;

    println!("    e [m]      ec   →   u [rpm]");
    for (e, ec) in [
        (0.0, 0.0),
        (0.3, 0.0),
        (0.45, 0.0),
        (0.1, -10.0),
        (-0.2, 5.0),
        (1.0, 50.0),
    ] {
        let u = sys.infer(&[e, ec])?;
        println!("{e:9.3} {ec:7.1}   → {:9.2}", tidy(u));
        let mirrored = sys.infer(&[-e, -ec])?;
        assert!(
            (u + mirrored).abs() < 1e-9,
            "odd symmetry broken at ({e}, {ec})"
        );
    }
    let u = sys.infer(&[0.3, 0.0])?;
    assert!(
        u > 0.0,
        "large positive e with ec = ZE must give a positive u, got {u}"
    );

    let trace = sys.infer_traced(&[0.1, -10.0])?;
    println!("\nat e = 0.1, ec = −10 these rules fire (rule index, strength):");
    for (r, s) in &trace.fired {
        let rule = &sys.rules()[*r];
        println!(
            "  #{r:2}: e {} ∧ ec {} → u {}  ({s:.3})",
            TERMS[rule.antecedent[0]], TERMS[rule.antecedent[1]], TERMS[rule.consequent]
        );
    }

    let s = sys.surface(7, 7)?;
    println!("\ncontrol surface u [rpm] at the term peaks (rows ec, columns e):");
    print!("{:>8}", "ec \\ e");
    for x in &s.xs {
        print!("{x:>8.2}");
    }
    println!();
    for (y, row) in s.ys.iter().zip(&s.z) {
        print!("{y:>8.1}");
        for z in row {
            print!("{:>8.0}", tidy(*z));
        }
        println!();
    }
    Ok(())
}
