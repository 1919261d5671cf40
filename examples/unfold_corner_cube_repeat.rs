//! Unfolds the corner cube 200 times (a fixed workload for instruction counting with
//! `valgrind --tool=callgrind`).
fn main() {
    let pattern = nanofold::read::load_pattern(
        std::path::Path::new("patterns/corner_cube.fold"),
        &nanofold::pattern::LoadOptions::default(),
    )
    .unwrap();
    for _ in 0..200 {
        std::hint::black_box(nanofold::unfold::unfold(&pattern, &Default::default()).unwrap());
    }
}
