//! Helpers shared by the integration tests.

/// A closed native vertex with `sectors` and fold angles `rho`, both in rad, creases unassigned.
pub fn native_json(sectors: &[f64], rho: &[f64]) -> String {
    let creases: Vec<String> = rho
        .iter()
        .map(|r| format!(r#"{{"assignment":"U","fold_angle":{r}}}"#))
        .collect();
    format!(
        r#"{{"chain":"closed","angle_unit":"rad","sector_angles":{sectors:?},"creases":[{}]}}"#,
        creases.join(",")
    )
}
