//! Criterion benches for the bridge (SPEC §8): M(θ), C(θ, θ̇)θ̇, the whole right-hand side,
//! and the step response to first collision at two tolerances. The example
//! `work_precision` prints each run's error beside its time.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DVector;
use nanofold::dynamics::simulate::{simulate, Method, SimulationSettings};
use nanofold::dynamics::Data;
use nanofold::scene::Scene;
use std::hint::black_box;
use std::path::Path;

fn bridge() -> Scene {
    Scene::load(Path::new("patterns/bridge_step.scene.json")).unwrap()
}

fn bench_terms(c: &mut Criterion) {
    let scene = bridge();
    let model = &scene.model;
    let mut data = Data::new(model);
    let angles = [0.7, 1.1, -0.4, 1.9];
    let rates = [1.0e3, -2.0e3, 5.0e3, 1.0e4];
    let torques = [1e-9; 4];
    let mut out = vec![0.0; 4];
    let mut accel = DVector::zeros(4);
    let mut group = c.benchmark_group("bridge");
    group.bench_function("mass_matrix", |b| {
        b.iter(|| {
            model.update_kinematics(black_box(&angles), &mut data);
            model.update_mass_matrix(&mut data);
        })
    });
    group.bench_function("coriolis_newton_euler", |b| {
        model.update_kinematics(&angles, &mut data);
        b.iter(|| {
            model.update_velocities(black_box(&rates), &mut data);
            model.coriolis_torques(&rates, &mut data, &mut out)
        })
    });
    group.bench_function("coriolis_christoffel_matrix", |b| {
        model.update_kinematics(&angles, &mut data);
        b.iter(|| {
            model.update_mass_matrix_derivative(&mut data);
            model.update_coriolis(black_box(&rates), &mut data);
        })
    });
    group.bench_function("accelerations", |b| {
        b.iter(|| {
            model
                .accelerations(black_box(&angles), &rates, &torques, &mut data, accel.as_mut_slice())
                .unwrap()
        })
    });
    group.finish();
}

fn bench_step(c: &mut Criterion) {
    let scene = bridge();
    let mut group = c.benchmark_group("bridge_step_to_collision");
    group.sample_size(10);
    for rtol in [1e-6, 1e-10] {
        let settings = SimulationSettings {
            rtol,
            method: Method::Tsit45,
            ..Default::default()
        };
        group.bench_function(format!("tsit45_rtol_{rtol:e}"), |b| {
            b.iter(|| simulate(&scene, &settings).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench_terms, bench_step);
criterion_main!(benches);
