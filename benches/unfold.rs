//! Criterion benches: unfolding each library pattern, and one energy + gradient evaluation.

use criterion::{criterion_group, criterion_main, Criterion};
use nanofold::geometry::sphere::Vec3;
use nanofold::pattern::{LoadOptions, VertexPattern};
use nanofold::unfold::{unfold, UnfoldModel, UnfoldSettings};
use nanofold::unfold::{EnergyKind, EnergyWorkspace};

fn library() -> Vec<VertexPattern> {
    let mut paths: Vec<_> = std::fs::read_dir("patterns")
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "fold"))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| nanofold::read::load_pattern(p, &LoadOptions::default()).unwrap())
        .collect()
}

fn bench_unfold(c: &mut Criterion) {
    let settings = UnfoldSettings::default();
    let mut group = c.benchmark_group("unfold");
    group.sample_size(20);
    for pattern in library() {
        group.bench_function(&pattern.name, |b| b.iter(|| unfold(&pattern, &settings).unwrap()));
    }
    group.finish();
}

fn bench_energy(c: &mut Criterion) {
    let pattern = nanofold::read::load_pattern(
        std::path::Path::new("patterns/corner_cube.fold"),
        &LoadOptions::default(),
    )
    .unwrap();
    let model = UnfoldModel::new(&pattern);
    let nodes = model.folded_nodes();
    let energy = EnergyKind::Separable.build(None);
    let mut ws = EnergyWorkspace::default();
    let mut grad = vec![Vec3::zeros(); nodes.len()];
    c.bench_function("energy+gradient corner_cube", |b| {
        b.iter(|| energy.value_and_gradient(&nodes, &model.arcs, &mut ws, &mut grad))
    });
}

criterion_group!(benches, bench_unfold, bench_energy);
criterion_main!(benches);
