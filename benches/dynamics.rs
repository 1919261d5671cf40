//! Criterion benches for the bridge (`docs/model.md#reference-devices`): M(θ), C(θ, θ̇)θ̇, the whole right-hand side,
//! and the step response to first collision at two tolerances. The example
//! `work_precision` prints each run's error beside its time.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DVector;
use nanofold::dynamics::algorithms::{
    coriolis_torques, forward_dynamics, update_coriolis_matrix, update_kinematics, update_mass_matrix,
    update_mass_matrix_derivative, update_velocities,
};
use nanofold::dynamics::scene::Scene;
use nanofold::dynamics::simulate::{simulate_scene, SimulationSettings};
use nanofold::dynamics::Data;
use nanofold::dynamics::Method;
use std::hint::black_box;
use std::path::Path;

fn bridge() -> Scene {
    nanofold::read::load_scene(Path::new("patterns/bridge_step.scene.json"))
        .and_then(|spec| spec.build())
        .unwrap()
}

fn bench_terms(c: &mut Criterion) {
    let scene = bridge();
    let model = &scene.strip().unwrap().model;
    let mut data = Data::new(model);
    let angles = [0.7, 1.1, -0.4, 1.9];
    let rates = [1.0e3, -2.0e3, 5.0e3, 1.0e4];
    let torques = [1e-9; 4];
    let mut out = vec![0.0; 4];
    let mut accel = DVector::zeros(4);
    let mut group = c.benchmark_group("bridge");
    group.bench_function("mass_matrix", |b| {
        b.iter(|| {
            update_kinematics(model, black_box(&angles), &mut data);
            update_mass_matrix(model, &mut data);
        })
    });
    group.bench_function("coriolis_newton_euler", |b| {
        update_kinematics(model, &angles, &mut data);
        b.iter(|| {
            update_velocities(model, black_box(&rates), &mut data);
            coriolis_torques(model, &rates, &mut data, &mut out)
        })
    });
    group.bench_function("coriolis_christoffel_matrix", |b| {
        update_kinematics(model, &angles, &mut data);
        b.iter(|| {
            update_mass_matrix_derivative(model, &mut data);
            update_coriolis_matrix(model, black_box(&rates), &mut data);
        })
    });
    group.bench_function("accelerations", |b| {
        b.iter(|| {
            forward_dynamics(
                model,
                black_box(&angles),
                &rates,
                &torques,
                &mut data,
                accel.as_mut_slice(),
            )
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
            b.iter(|| simulate_scene(&scene, &settings).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench_terms, bench_step);
criterion_main!(benches);
