//! A full-size machine from the 1:30 scale model by Froude similarity
//! (SPEC §9): the planner's equations hold at any size, so a machine λ
//! times as large, digging a pile λ times as large, in a material of the
//! same density whose cutting resistance per unit area grows as λ (the
//! same stress at the same depth under gravity), digs the same path
//! λ times as large, λ^½ times as slowly, with λ³ times the mass.
//!
//! | quantity | law | scale model → λ = 30 |
//! |---|---|---|
//! | lengths (Table 1, dipper, handle, H_kk, the bends, g_x, g_y) | × λ | dipper 0.12 m wide → 3.6 m |
//! | capacity V_cd | × λ³ | 8.107e-4 m³ → 21.9 m³ |
//! | masses | × λ³ | dipper 0.8 kg → 21.6 t |
//! | forces (c11, c12) | × λ³ | hoist 400 N → 10.8 MN |
//! | times (c3, c4, t_d) | × λ^½ | 9–15 s → 49–82 s |
//! | speeds (c8, c10) | × λ^½ | 0.1 m/s → 0.55 m/s |
//! | powers (c13, c14) | × λ^3.5 | 15 W → 2.22 MW |
//! | cutting resistance k_F (Pa) | × λ | 16.8 kPa → 503 kPa |
//! | a_x6, a_y6 (m/s⁶) | × λ⁻² | |
//! | angles, fills, ψ, ε, density | × 1 | |
//! | k1 (on f1 (J/kg) ∝ λ), k2 (on f2 (s/kg) ∝ λ^−2.5) | × λ⁻¹, × λ^2.5 | f itself unchanged |
//!
//! Energy (force × length) grows as λ⁴. The weights k1 and k2 are scaled so
//! that the objective of [RS eq. 27] has the same value on a path and on its
//! image: the planner then ranks the full-size paths as it ranks the
//! model's, and plans the image of the model's plan (tested).
//!
//! What the laws give and a real machine does not: the model's dig of
//! 9–15 s becomes 49–82 s at full size, where a WK-class shovel digs in
//! 12–20 s; its drives are slow for its size (the model's hoist rating is
//! 15 W). Tonnes per hour of a shift on this machine are therefore about a
//! third of a real one's; SPEC §9 fixes these laws so the machine stays
//! the paper's.

use serde::Serialize;

use crate::profile::MachineProfile;

/// The similarity of a machine to the model it was scaled from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Similarity {
    /// λ: lengths of the machine ÷ the model's.
    pub lambda: f64,
}

impl Similarity {
    /// The paper's scale: the model is 1:30.
    pub const PAPER: Similarity = Similarity { lambda: 30.0 };

    /// A length (m).
    pub fn length(&self, v: f64) -> f64 {
        v * self.lambda
    }

    /// A time (s).
    pub fn time(&self, v: f64) -> f64 {
        v * self.lambda.sqrt()
    }

    /// A speed (m/s).
    pub fn speed(&self, v: f64) -> f64 {
        v * self.lambda.sqrt()
    }

    /// A mass (kg) or a force (N) (λ³), or a volume (m³).
    pub fn cube(&self, v: f64) -> f64 {
        v * self.lambda.powi(3)
    }

    /// An energy (J) (λ⁴).
    pub fn energy(&self, v: f64) -> f64 {
        v * self.lambda.powi(4)
    }

    /// A power (W) (λ^3.5).
    pub fn power(&self, v: f64) -> f64 {
        v * self.lambda.powf(3.5)
    }

    /// The machine λ times as large as `model` (module docs give the laws).
    pub fn machine(&self, model: &MachineProfile) -> MachineProfile {
        let l = self.lambda;
        let mut p = model.clone();
        let g = &mut p.geometry;
        for v in [
            &mut g.sheave_radius_m,
            &mut g.pinion_radius_m,
            &mut g.boom_length_m,
            &mut g.saddle_to_sheave_m,
            &mut g.saddle_to_bail_m,
            &mut g.saddle_to_tip_m,
            &mut g.saddle_height_m,
        ] {
            *v *= l;
        }
        g.toe_distance_m = g.toe_distance_m.map(|d| d * l);
        let d = &mut p.dipper;
        d.width_m *= l;
        d.length_m *= l;
        d.height_m *= l;
        d.capacity_m3 = self.cube(d.capacity_m3);
        d.mass_kg = self.cube(d.mass_kg);
        p.handle.length_m *= l;
        p.handle.mass_kg = self.cube(p.handle.mass_kg);
        p.material.cutting_resistance_pa *= l;
        let m = &mut p.limits;
        m.time_min_s = self.time(m.time_min_s);
        m.time_max_s = self.time(m.time_max_s);
        m.hoist_speed_max_m_s = self.speed(m.hoist_speed_max_m_s);
        m.crowd_speed_max_m_s = self.speed(m.crowd_speed_max_m_s);
        m.hoist_force_max_n = self.cube(m.hoist_force_max_n);
        m.crowd_force_max_n = self.cube(m.crowd_force_max_n);
        m.hoist_power_max_w = self.power(m.hoist_power_max_w);
        m.crowd_power_max_w = self.power(m.crowd_power_max_w);
        m.hopper_height_m *= l;
        p.objective.k1 /= l;
        p.objective.k2 *= l.powf(2.5);
        let s = &mut p.search;
        for r in [&mut s.bend_x_m, &mut s.bend_y_m, &mut s.gx_m, &mut s.gy_m] {
            *r = r.map(|v| v * l);
        }
        // a₆ (m/s⁶): a length over a time to the sixth.
        for r in [&mut s.ax6, &mut s.ay6] {
            *r = r.map(|v| v / (l * l));
        }
        s.td_s = s.td_s.map(|v| self.time(v));
        p
    }

    /// The image of a model decision [a_x6, a_y6, t_d, g_x, g_y] on the
    /// machine λ times as large.
    pub fn decision(&self, model: &[f64; 5]) -> [f64; 5] {
        let l = self.lambda;
        [
            model[0] / (l * l),
            model[1] / (l * l),
            self.time(model[2]),
            self.length(model[3]),
            self.length(model[4]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dig_surface::DigSurface;
    use crate::plan::DigModel;
    use crate::trajectory::Decision;
    use approx::assert_relative_eq;
    use autoshovel_terrain::PileShape;

    #[test]
    fn a_machine_thirty_times_as_large_digs_the_image_of_the_models_path() {
        // The same pile at 1:30 and its image at full size, a feasible
        // model decision (the model's own plan) and its image: the outcome
        // scales as the laws say, f is unchanged, and every constraint
        // (over its limit) is the same.
        let s = Similarity::PAPER;
        let l = s.lambda;
        let model_profile = MachineProfile::scale_model();
        let big_profile = s.machine(&model_profile);
        for shape in [PileShape::Typical, PileShape::Convex] {
            let surface = crate::paper::paper_pile(&model_profile, shape)
                .unwrap()
                .surface(model_profile.dipper.width_m);
            let (x0, x1) = surface.x_range();
            let image = DigSurface::from_fn(
                |x, _| l * surface.height(x / l),
                big_profile.dipper.width_m,
                l * x0,
                l * x1,
                "image",
            )
            .with_deepest_cut(l * crate::dig_surface::DEEPEST_CUT_M);
            let small = DigModel::new(&model_profile, surface).unwrap();
            let big = DigModel::new(&big_profile, image).unwrap();
            let search = crate::plan::search_preset();
            let d = crate::plan::plan_dig(&small, &search, &[])
                .unwrap()
                .outcome
                .decision;
            let x = [d.ax6, d.ay6, d.td_s, d.gx_m, d.gy_m];
            let a = small.evaluate(&Decision::from_slice(&x));
            let b = big.evaluate(&Decision::from_slice(&s.decision(&x)));
            assert!(a.feasible(), "{:?}", a.violated());
            // (the image may break a bound the plan sits on by the
            // profile's sampling: its measures are compared below)
            assert_relative_eq!(b.volume_m3, s.cube(a.volume_m3), max_relative = 1e-3);
            assert_relative_eq!(b.m_dig_kg, s.cube(a.m_dig_kg), max_relative = 1e-3);
            assert_relative_eq!(
                b.hoist_energy_j,
                s.energy(a.hoist_energy_j),
                max_relative = 1e-3
            );
            assert_relative_eq!(
                b.crowd_energy_j,
                s.energy(a.crowd_energy_j),
                max_relative = 1e-3
            );
            assert_relative_eq!(b.f, a.f, max_relative = 1e-3);
            assert_relative_eq!(b.fill_factor, a.fill_factor, max_relative = 1e-3);
            for i in 0..18 {
                let (ca, cb) = (a.measured[i], b.measured[i]);
                let (sa, sb) = (small.constraint_scale(i), big.constraint_scale(i));
                assert!(
                    (ca / sa - cb / sb).abs() < 1e-3 * (1.0 + (ca / sa).abs()),
                    "c{}: {ca} of {sa} vs {cb} of {sb}",
                    i + 1
                );
            }
        }
    }

    #[test]
    fn the_full_size_dipper_is_wk_class() {
        let p = Similarity::PAPER.machine(&MachineProfile::scale_model());
        assert_relative_eq!(
            p.dipper.capacity_m3,
            8.107e-4 * 27_000.0,
            max_relative = 1e-12
        );
        assert!((20.0..25.0).contains(&p.dipper.capacity_m3));
        assert_relative_eq!(p.limits.hoist_power_max_w, 15.0 * 30f64.powf(3.5));
        assert_relative_eq!(p.search.td_s[0], 9.0 * 30f64.sqrt());
    }
}
