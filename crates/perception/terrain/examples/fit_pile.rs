//! Scan each of the four piles of the rope-shovel paper's Fig. 7, level the
//! scan from its floor ([RS eq. 11]–[RS eq. 12]), cut the floor away and fit [RS eq. 21] on the
//! 8 × 8 grid; print the tilt error, the degree, R² and the surface as a
//! polynomial in x, y. Asserts the targets: tilt within 0.2°, R² > 0.95.
//!
//! `cargo run --release -p autoshovel-terrain --example fit_pile`

use autoshovel_point_cloud::PointCloud;
use autoshovel_terrain::{
    estimate_tilt, fit_surface, generate_pile, level, FitParams, PileParams, PileShape, TiltParams,
};

fn main() {
    for shape in PileShape::ALL {
        let p = PileParams {
            shape,
            points: 50_000,
            ..PileParams::default()
        };
        let scan = generate_pile(&p).expect("valid parameters");
        let tilt = estimate_tilt(&scan, &TiltParams::default()).expect("a floor");
        let flat = level(&scan, tilt.roll_rad, tilt.pitch_rad);
        // Pass-through: keep what stands 0.2 m above the floor.
        let pile = PointCloud::new(
            flat.points
                .into_iter()
                .filter(|q| f64::from(q[2]) >= tilt.floor_height_m + 0.2)
                .collect(),
        );
        let fit = fit_surface(&pile, &FitParams::default()).expect("R² > 0.95");
        let d_roll = (tilt.roll_rad - p.roll_rad).to_degrees();
        let d_pitch = (tilt.pitch_rad - p.pitch_rad).to_degrees();
        println!(
            "{:>14}: roll {:+.3}° (err {d_roll:+.4}°), pitch {:+.3}° (err {d_pitch:+.4}°), \
             degree {}, {} samples, R² {:.4}, adjusted {:.4}, rms {:.3} m",
            shape.name(),
            tilt.roll_rad.to_degrees(),
            tilt.pitch_rad.to_degrees(),
            fit.degree,
            fit.samples.len(),
            fit.r2,
            fit.adjusted_r2,
            fit.rms_residual_m
        );
        let terms: Vec<String> = fit
            .coefficients_xy()
            .iter()
            .map(|t| format!("{:+.4e}·x^{}y^{}", t.coefficient, t.x_power, t.y_power))
            .collect();
        println!("{:>14}  z = {}", "", terms.join(" "));
        assert!(d_roll.abs() < 0.2 && d_pitch.abs() < 0.2);
        assert!(fit.r2 > 0.95);
    }
}
