//! `validate-dig` against measurements simulated from a real plan with known
//! errors ([RS §5], [RS Table 6], [RS Fig. 20]): the delay, the time scale,
//! the sensor gains and the mass deviation that went in come back out.

use std::path::Path;
use std::sync::OnceLock;

use approx::assert_relative_eq;
use autoshovel_optim::GwoParams;
use autoshovel_rope_shovel_dig::validate::{
    simulate_measurement, validate, AlignParams, MeasuredRecord, MeasurementModel, PlannedRecord,
    Validation,
};
use autoshovel_rope_shovel_dig::{
    gwo_preset, plan_dig, DigModel, DigSearch, DigSurface, MachineProfile,
};
use autoshovel_terrain::PileShape;

/// The plan of the typical pile (seed 1, the paper's GWO setting), made once.
fn planned() -> &'static PlannedRecord {
    static PLAN: OnceLock<PlannedRecord> = OnceLock::new();
    PLAN.get_or_init(|| {
        let p = MachineProfile::scale_model();
        let model = DigModel::new(
            &p,
            DigSurface::from_shape(PileShape::Typical, p.dipper.width_m),
        )
        .unwrap();
        let gwo: DigSearch = GwoParams {
            seed: 1,
            ..gwo_preset()
        }
        .into();
        let plan = plan_dig(&model, &gwo, &[]).unwrap();
        PlannedRecord::from_plan("typical plan", "typical", &model, &plan)
    })
}

fn check(model: &MeasurementModel) -> (MeasuredRecord, Validation) {
    let m = simulate_measurement(planned(), model, Path::new("simulated.csv")).unwrap();
    let v = validate(planned(), &m, &AlignParams::default()).unwrap();
    (m, v)
}

#[test]
fn a_perfect_measurement_matches_its_plan() {
    // Logged at the plan's own sample times: the same polyline.
    let p = planned();
    let (_, v) = check(&MeasurementModel {
        sample_period_s: p.td_s / (p.forces.t_s.len() - 1) as f64,
        ..MeasurementModel::default()
    });
    let s = &v.summary;
    eprintln!("perfect: {:#?}", s.alignment);
    assert_relative_eq!(s.alignment.delay_s, 0.0, epsilon = 1e-3);
    assert_relative_eq!(s.alignment.time_scale, 1.0, epsilon = 1e-4);
    for f in [&s.hoist_force, &s.crowd_force] {
        eprintln!("perfect: {f:?}");
        assert_relative_eq!(f.r_squared, 1.0, epsilon = 1e-5);
        assert_relative_eq!(f.pearson_r, 1.0, epsilon = 1e-5);
        assert_relative_eq!(f.gain, 1.0, epsilon = 1e-4);
        assert!(f.rms_difference_n < 1e-3 * f.peak_planned_n, "{f:?}");
        assert!(f.peak_difference_n.abs() < 1e-3 * f.peak_planned_n, "{f:?}");
    }
    let mass = s.mass_kg.unwrap();
    assert_relative_eq!(mass.difference, 0.0, epsilon = 1e-15);
    assert_relative_eq!(mass.relative_deviation_pct, 0.0, epsilon = 1e-12);
    assert_relative_eq!(s.dig_time_s.relative_deviation_pct, 0.0, epsilon = 0.01);
    for t in [s.rope_length.unwrap(), s.handle_extension.unwrap()] {
        assert!(t.rms_difference_m < 1e-5, "{t:?}");
    }
    // Every plan sample lies in the record, which runs 0.5 s past the dig.
    assert_eq!(s.compared_samples, s.planned_samples);
}

#[test]
fn known_delay_gains_time_scale_and_mass_are_recovered() {
    let truth = MeasurementModel::testbed();
    let (m, v) = check(&truth);
    let s = &v.summary;
    let a = &s.alignment;
    let p = planned();
    eprintln!(
        "testbed: {a:#?}\nhoist {:?}\ncrowd {:?}",
        s.hoist_force, s.crowd_force
    );
    eprintln!("mass {:?}\ntime {:?}", s.mass_kg, s.dig_time_s);
    // The delay within half the logger's sample period.
    assert_relative_eq!(
        a.delay_s,
        truth.delay_s,
        epsilon = 0.5 * truth.sample_period_s
    );
    assert_relative_eq!(a.time_scale, truth.time_scale, epsilon = 1e-3);
    // The gains within 1 %.
    assert_relative_eq!(s.hoist_force.gain, truth.gain_hoist, max_relative = 0.01);
    assert_relative_eq!(s.crowd_force.gain, truth.gain_crowd, max_relative = 0.01);
    // The mass: exactly what went in.
    let mass = s.mass_kg.unwrap();
    assert_eq!(mass.planned, p.m_dig_kg);
    assert_eq!(mass.measured, m.mass_kg.unwrap());
    assert_relative_eq!(mass.difference, truth.mass_offset_kg, epsilon = 1e-12);
    assert_relative_eq!(
        mass.relative_deviation_pct,
        100.0 * truth.mass_offset_kg / (p.m_dig_kg + truth.mass_offset_kg),
        epsilon = 1e-9
    );
    // The dig time: s · t_d.
    assert_relative_eq!(
        s.dig_time_s.measured,
        truth.time_scale * p.td_s,
        epsilon = 1e-3 * p.td_s
    );
    // A gain error lowers R², not r.
    for f in [&s.hoist_force, &s.crowd_force] {
        assert!(f.r2_pearson > 0.95, "{f:?}");
        assert!(f.r_squared < f.r2_pearson, "{f:?}");
    }
}

#[test]
fn records_that_start_late_or_long_before_the_dig_are_aligned() {
    for delay_s in [-0.25, 0.0, 1.5, 3.2] {
        let truth = MeasurementModel {
            delay_s,
            noise_n: 1.0,
            seed: 7,
            ..MeasurementModel::default()
        };
        let (_, v) = check(&truth);
        let a = &v.summary.alignment;
        eprintln!(
            "delay {delay_s}: found {} (scale {})",
            a.delay_s, a.time_scale
        );
        // Within half the sample period: with noise, τ and s trade off along a
        // ridge (a later start and a faster clock look alike).
        assert_relative_eq!(a.delay_s, delay_s, epsilon = 0.5 * truth.sample_period_s);
        assert_relative_eq!(a.time_scale, 1.0, epsilon = 5e-4);
    }
}

#[test]
fn a_record_outside_the_lag_window_is_refused_with_the_window() {
    let truth = MeasurementModel {
        delay_s: 3.0,
        ..MeasurementModel::default()
    };
    let m = simulate_measurement(planned(), &truth, Path::new("late.csv")).unwrap();
    let params = AlignParams {
        max_lag_s: Some(0.5),
        max_stretch: 0.0,
        min_overlap: 0.9,
    };
    // Within ±0.5 s the dig still overlaps the record, but never by 90 %
    // once the record is cut at its start.
    let mut cut = m.clone();
    let keep = cut.forces.t_s.iter().position(|&t| t >= 5.0).unwrap();
    for v in [
        &mut cut.forces.t_s,
        &mut cut.forces.hoist_force_n,
        &mut cut.forces.crowd_force_n,
    ] {
        v.drain(..keep);
    }
    cut.forces.rope_length_m = None;
    cut.forces.handle_extension_m = None;
    let e = validate(planned(), &cut, &params).unwrap_err().to_string();
    assert!(e.starts_with("late.csv: the record (5 s to"), "{e}");
    assert!(e.contains("±0.5 s"), "{e}");
    // The uncut record aligns within the default window.
    assert!(validate(planned(), &m, &AlignParams::default()).is_ok());
}

#[test]
fn settings_out_of_range_are_named() {
    let bad = MeasurementModel {
        sample_period_s: 0.0,
        ..MeasurementModel::testbed()
    };
    let e = simulate_measurement(planned(), &bad, Path::new("m.csv")).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("MeasurementModel.sample_period_s = 0"),
        "{e}"
    );
    let m =
        simulate_measurement(planned(), &MeasurementModel::testbed(), Path::new("m.csv")).unwrap();
    let params = AlignParams {
        max_stretch: 0.7,
        ..AlignParams::default()
    };
    let e = validate(planned(), &m, &params).unwrap_err();
    assert!(
        e.to_string().starts_with("AlignParams.max_stretch = 0.7"),
        "{e}"
    );
}
