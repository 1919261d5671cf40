//! Every bad input gets a clear error naming the field and the value.

use nanofold::pattern::LoadOptions;

fn error_of(text: &str) -> String {
    match nanofold::read::parse_pattern(text, "test", "test.json", &LoadOptions::default()) {
        Ok(_) => panic!("accepted bad input: {text}"),
        Err(e) => e.to_string(),
    }
}

fn native(sectors: &str, creases: &str) -> String {
    format!(r#"{{"chain":"closed","angle_unit":"deg","sector_angles":{sectors},"creases":[{creases}]}}"#)
}

const FOUR: &str = r#"{"assignment":"V","fold_angle":0},{"assignment":"V","fold_angle":0},{"assignment":"V","fold_angle":0},{"assignment":"V","fold_angle":0}"#;

#[test]
fn malformed_json() {
    assert!(error_of("{ not json").contains("malformed JSON"));
}

#[test]
fn missing_keys() {
    assert!(error_of(r#"{"chain":"closed","angle_unit":"deg","creases":[]}"#).contains("missing key `sector_angles`"));
    let fold = r#"{"vertices_coords":[[0,0],[1,0],[0,1]],"edges_vertices":[[0,1],[0,2]]}"#;
    assert!(error_of(fold).contains("missing key `edges_assignment`"));
    let fold = r#"{"vertices_coords":[[0,0],[1,0],[0,1]],"edges_vertices":[[0,1],[0,2]],"edges_assignment":["V","V"]}"#;
    assert!(error_of(fold).contains("edges_foldAngle"));
}

#[test]
fn non_finite_numbers() {
    // JSON has no NaN; an overflowing literal is refused by the parser.
    assert!(error_of(&native("[90, 90, 90, 1e999]", FOUR)).contains("malformed JSON"));
    let fold = r#"{"vertices_coords":[[0,0],[1,"x"]],"edges_vertices":[],"edges_assignment":[],"edges_foldAngle":[]}"#;
    let e = error_of(fold);
    assert!(
        e.contains("vertices_coords[1]") && e.contains("expected a number"),
        "{e}"
    );
}

#[test]
fn zero_or_negative_sectors() {
    let e = error_of(&native("[0, 120, 120, 120]", FOUR));
    assert!(e.contains("sector_angles[0]") && e.contains("positive"), "{e}");
    let e = error_of(&native("[100, -10, 130, 140]", FOUR));
    assert!(e.contains("sector_angles[1]"), "{e}");
}

#[test]
fn too_much_paper_at_a_boundary_vertex() {
    let text = r#"{"chain":"open","angle_unit":"deg","sector_angles":[200, 200],"creases":[{"assignment":"V","fold_angle":10}]}"#;
    let e = error_of(text);
    assert!(e.contains("sector_angles") && e.contains("400"), "{e}");
}

#[test]
fn fold_angle_out_of_range() {
    let creases = r#"{"assignment":"V","fold_angle":190},{"assignment":"V","fold_angle":0},{"assignment":"V","fold_angle":0},{"assignment":"V","fold_angle":0}"#;
    let e = error_of(&native("[90, 90, 90, 90]", creases));
    assert!(e.contains("creases[0].fold_angle") && e.contains("190"), "{e}");
}

#[test]
fn fold_angle_sign_contradicts_assignment() {
    let creases = r#"{"assignment":"M","fold_angle":30},{"assignment":"V","fold_angle":0},{"assignment":"M","fold_angle":30},{"assignment":"V","fold_angle":0}"#;
    let e = error_of(&native("[90, 90, 90, 90]", creases));
    assert!(e.contains("creases[0].fold_angle") && e.contains("mountain"), "{e}");
}

#[test]
fn loop_closure_violation_reports_the_residual() {
    let creases = r#"{"assignment":"V","fold_angle":30},{"assignment":"V","fold_angle":0},{"assignment":"M","fold_angle":-30},{"assignment":"V","fold_angle":0}"#;
    let e = error_of(&native("[90, 90, 90, 90]", creases));
    assert!(e.contains("loop closure") && e.contains("residual 1.047e0"), "{e}");
}

#[test]
fn cut_and_join_edges_are_refused() {
    let fold = r#"{"vertices_coords":[[0,0],[1,0],[-1,0]],"edges_vertices":[[0,1],[0,2]],"edges_assignment":["C","V"],"edges_foldAngle":[0,0]}"#;
    let e = error_of(fold);
    assert!(e.contains("edges_assignment[0]") && e.contains("\"C\""), "{e}");
}

#[test]
fn multi_vertex_patterns_are_refused() {
    // Two crease vertices: (0,0) and (2,0), joined by a crease.
    let fold = r#"{"vertices_coords":[[0,0],[2,0],[-1,0],[3,0]],"edges_vertices":[[0,1],[0,2],[1,3]],"edges_assignment":["V","V","V"],"edges_foldAngle":[10,10,10]}"#;
    assert_eq!(
        error_of(fold),
        "2 vertices with creases; only single-vertex patterns are supported"
    );
}

#[test]
fn unknown_native_field_and_values() {
    assert!(error_of(&native("[90, 90, 90, 90]", FOUR).replace("\"deg\"", "\"grad\"")).contains("angle_unit"));
    assert!(error_of(&native("[90, 90, 90, 90]", FOUR).replace("closed", "loop")).contains("chain"));
    let e = error_of(&native("[90, 90, 90, 90]", &FOUR.replacen("\"V\"", "\"X\"", 1)));
    assert!(e.contains("creases[0].assignment"), "{e}");
}

#[test]
fn flat_folded_input_is_backed_off_by_the_documented_rule() {
    // Half-paper folded exactly flat: coincident sectors, infinite energy.
    let text = r#"{"vertices_coords":[[0,0],[1,0],[-1,0],[1,1],[-1,1],[-1,-1],[1,-1]],
        "edges_vertices":[[0,1],[0,2],[1,3],[3,4],[4,2],[2,5],[5,6],[6,1]],
        "edges_assignment":["V","V","B","B","B","B","B","B"],"edges_foldAngle":[180,180,0,0,0,0,0,0]}"#;
    let pattern = nanofold::read::parse_pattern(text, "flat_folded", "t", &LoadOptions::default()).unwrap();
    let report = nanofold::unfold::unfold(&pattern, &Default::default()).unwrap();
    assert_eq!(report.verdict, nanofold::unfold::Verdict::Flat);
    assert!(report.adjustments.iter().any(|a| a.contains("flat-folded")));
    assert!(report.energy_initial.is_finite());
}

#[test]
fn locked_key_must_hold_one_boolean_per_edge() {
    let base = r#"{"vertices_coords":[[0,0],[1,0],[-1,0]],"edges_vertices":[[0,1],[0,2]],"edges_assignment":["V","V"],"edges_foldAngle":[10,10]"#;
    let e = error_of(&format!(r#"{base},"edges_nanofold:locked":[true]}}"#));
    assert!(e.contains("edges_nanofold:locked") && e.contains("2 booleans"), "{e}");
    let e = error_of(&format!(r#"{base},"edges_nanofold:locked":[true,"yes"]}}"#));
    assert!(e.contains("edges_nanofold:locked[1]"), "{e}");
}

#[test]
fn a_sector_of_a_full_turn_or_more_is_refused() {
    // Found by tests/fuzz.rs: a huge sector was split into that many quarter turns (out of memory).
    let message = error_of(&native("[90, 90, 90, 1e300]", FOUR));
    assert!(message.contains("less than 360°"), "{message}");
}

#[test]
fn creases_on_both_sides_of_the_boundary_edges_are_refused() {
    // Found by tests/fuzz.rs: moving the sheet corner's vertex put its creases outside the
    // paper's wedge, and the importer dropped one (then indexed past the crease list).
    let text = std::fs::read_to_string("patterns/sheet_corner.fold").unwrap();
    let mut fold: serde_json::Value = serde_json::from_str(&text).unwrap();
    fold["vertices_coords"][0] = serde_json::json!([0.0, 180.0]);
    let message = error_of(&fold.to_string());
    assert!(
        message.contains("both sides") && message.contains("vertices_coords"),
        "{message}"
    );
}

/// A cut edge is refused for what it is, whichever reader meets it first: no model of
/// nanofold takes cuts (a single vertex's reader once said "not supported by a
/// single-vertex model", as if another would).
#[test]
fn a_cut_edge_is_refused_for_every_model() {
    let mut vertex: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/miura_vertex.fold").unwrap()).unwrap();
    let letters = vertex["edges_assignment"].as_array_mut().unwrap();
    let first = letters.iter().position(|l| l == "M" || l == "V").unwrap();
    letters[first] = "C".into();
    let message = match nanofold::commands::Pattern::parse(
        &vertex.to_string(),
        "cut",
        "cut",
        &nanofold::pattern::LoadOptions::default(),
    ) {
        Ok(_) => panic!("a cut edge was read"),
        Err(e) => e.to_string(),
    };
    assert!(
        message.contains("edges_assignment") && message.contains("\"C\""),
        "{message}"
    );
    assert!(
        message.contains("one disc") && !message.contains("single-vertex model"),
        "{message}"
    );
}

/// The contact test's pair budget is validated by name: none at all, or past 10⁶ per panel
/// (a budget that large no longer bounds anything), is refused.
#[test]
fn a_contact_pair_budget_out_of_range_is_named() {
    use nanofold::prelude::*;
    let pattern = Pattern::open("patterns/many/miura_4x4.fold".as_ref(), &LoadOptions::default()).unwrap();
    for bad in [0, 2_000_000] {
        let mut settings = Settings::default();
        settings.fold.contact.pairs_per_panel = bad;
        let message = match fold(&pattern, &settings) {
            Ok(_) => panic!("a budget of {bad} pairs per panel was taken"),
            Err(e) => e.to_string(),
        };
        assert!(
            message.contains("pairs_per_panel") && message.contains(&bad.to_string()),
            "{message}"
        );
    }
}
