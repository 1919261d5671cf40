//! `nanofold export mujoco` against the real client: MuJoCo (its Python wheel, installed by
//! `scripts/test.sh`) loads the exported MJCF and integrates it (RK4), and its first contact
//! is compared with `nanofold simulate`'s, for the bridge (a strip) and the corner cube's step
//! 1 (a closed loop). Without the wheel the MuJoCo comparisons say so and pass, unless
//! NANOFOLD_REQUIRE_CLIENTS is set (as `scripts/test.sh` and CI set it).

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn nanofold() -> Command {
    Command::new(env!("CARGO_BIN_EXE_nanofold"))
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("nanofold-mujoco-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn python() -> Option<PathBuf> {
    match std::env::var_os("NANOFOLD_PYTHON") {
        Some(path) => Some(PathBuf::from(path)),
        None => {
            assert!(
                std::env::var_os("NANOFOLD_REQUIRE_CLIENTS").is_none(),
                "NANOFOLD_REQUIRE_CLIENTS is set but NANOFOLD_PYTHON is not"
            );
            // Written past the test harness's capture (which takes only the print macros), once,
            // so a plain `cargo test` shows it.
            static SAID: std::sync::Once = std::sync::Once::new();
            SAID.call_once(|| {
                use std::io::Write as _;
                let _ = writeln!(
                    std::io::stderr(),
                    "NOTICE: MuJoCo comparison not run: use scripts/test.sh (it installs MuJoCo's Python wheel)"
                );
            });
            None
        }
    }
}

fn export(scene: &Path, timestep: f64, out: &Path) -> String {
    let status = nanofold()
        .args(["export", "mujoco"])
        .arg(scene)
        .args(["--timestep", &timestep.to_string(), "--out"])
        .arg(out)
        .output()
        .unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    std::fs::read_to_string(out).unwrap()
}

fn simulate_scene(scene: &Path, dir: &Path) -> Value {
    let out = nanofold()
        .arg("simulate")
        .arg(scene)
        .args(["--json", "--out"])
        .arg(dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn run_mujoco(python: &Path, model: &Path, t_max_us: f64) -> Value {
    let out = Command::new(python)
        .arg("tests/mujoco/nanofold_mujoco.py")
        .arg(model)
        .arg(t_max_us.to_string())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Every `attribute="…"` number in the MJCF.
fn numbers(mjcf: &str, attribute: &str) -> Vec<f64> {
    let key = format!(" {attribute}=\"");
    mjcf.match_indices(&key)
        .map(|(at, _)| {
            let rest = &mjcf[at + key.len()..];
            rest[..rest.find('"').unwrap()].parse::<f64>().unwrap()
        })
        .collect()
}

/// The MJCF carries the scene's plates, hinges and step torques in its units (µm, pg, µs),
/// checked against the scene as nanofold builds it.
#[test]
fn the_exported_bridge_carries_the_scenes_masses_stiffnesses_and_torques() {
    let dir = temp_dir("bridge-units");
    let file = dir.join("bridge.xml");
    let mjcf = export(Path::new("patterns/bridge_step.scene.json"), 1e-8, &file);
    let scene = nanofold::read::load_scene(Path::new("patterns/bridge_step.scene.json"))
        .unwrap()
        .build()
        .unwrap();
    let chain = scene.strip().unwrap();
    let masses = numbers(&mjcf, "mass");
    let expected: Vec<f64> = chain.model.plates().iter().map(|p| p.mass / 1e-12).collect();
    assert_eq!(masses.len(), expected.len());
    for (m, e) in masses.iter().zip(&expected) {
        assert!((m / e - 1.0).abs() < 1e-11, "{m} {e}");
    }
    let stiffness = numbers(&mjcf, "stiffness");
    for (k, joint) in stiffness.iter().zip(chain.model.joints()) {
        assert!((k / (joint.stiffness / 1e-12) - 1.0).abs() < 1e-11);
    }
    // One actuator per actuated hinge: τ = K θ_target (here 90°).
    let torques: Vec<f64> = mjcf
        .match_indices("biasprm=\"")
        .map(|(at, _)| {
            let rest = &mjcf[at + 9..];
            rest.split_whitespace().next().unwrap().parse().unwrap()
        })
        .collect();
    assert_eq!(torques.len(), 4);
    for (t, joint) in torques.iter().zip(chain.model.joints()) {
        assert!((t / (joint.stiffness / 1e-12 * std::f64::consts::FRAC_PI_2) - 1.0).abs() < 1e-11);
    }
    assert_eq!(numbers(&mjcf, "timestep"), vec![1e-2]);
    // A time step above a twentieth of the fastest period is refused by flag, nothing written.
    let bad = dir.join("bad.xml");
    let out = nanofold()
        .args([
            "export",
            "mujoco",
            "patterns/bridge_step.scene.json",
            "--timestep",
            "1e-6",
            "--out",
        ])
        .arg(&bad)
        .output()
        .unwrap();
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("--timestep"));
    assert!(!bad.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A network's MJCF: the cube net's front holds each actuator off until its crease's release
/// time (custom numerics, µs, as the scene's front sets them), and the bodies carry the
/// panels' mass (every panel but the anchored one, which is the world); the Miura sheet's
/// light loop bodies take shares of their panels' mass, so the moving total is unchanged.
#[test]
fn the_exported_network_carries_its_front_and_its_panels_mass() {
    let dir = temp_dir("network-export");
    for scene_path in [
        "patterns/devices/cube_closes.scene.json",
        "patterns/devices/miura_sheet.scene.json",
    ] {
        let mjcf = export(Path::new(scene_path), 1e-8, &dir.join("network.xml"));
        let scene = nanofold::read::load_scene(Path::new(scene_path))
            .unwrap()
            .build()
            .unwrap();
        let model = scene.network().unwrap();
        let total: f64 = model.bodies.iter().map(|b| b.mass).sum();
        let anchored = model.bodies[model.anchored_panel].mass;
        let exported: f64 = numbers(&mjcf, "mass").iter().sum::<f64>() * 1e-12;
        // The anchored panel is the world; a light body standing for it carries a share.
        let on_ground = mjcf.matches("body2=\"world\"").count() / 3;
        if mjcf.matches("<connect").count() == 0 {
            assert!(!mjcf.contains("<equality>"));
        }
        let expected = total - anchored / (on_ground + 1) as f64;
        assert!(
            (exported / expected - 1.0).abs() < 1e-10,
            "{scene_path}: {exported} {expected}"
        );
        let release = |e: usize| {
            let key = format!("nanofold:release_time:crease_{e}\" data=\"");
            mjcf.find(&key).map(|at| {
                let rest = &mjcf[at + key.len()..];
                rest[..rest.find('"').unwrap()].parse::<f64>().unwrap() * 1e-6
            })
        };
        let key = &mjcf[mjcf.find("<key ").unwrap()..];
        let actuators: Vec<usize> = mjcf
            .match_indices("<general name=\"stress_crease_")
            .map(|(at, _)| {
                let rest = &mjcf[at + 29..];
                rest[..rest.find('"').unwrap()].parse().unwrap()
            })
            .collect();
        // No ctrl in the key: every actuator's is 0.
        let ctrl: Vec<f64> = match key.find("ctrl=\"") {
            Some(at) => key[at + 6..at + 6 + key[at + 6..].find('"').unwrap()]
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect(),
            None => vec![0.0; actuators.len()],
        };
        assert_eq!(actuators.len(), ctrl.len());
        for (&e, &u) in actuators.iter().zip(&ctrl) {
            let c = model.folding.pattern.creases.iter().position(|&x| x == e).unwrap();
            let hinge = &model.forcing.hinges[c];
            match release(e) {
                Some(t) => {
                    assert!((t / hinge.release_time - 1.0).abs() < 1e-12, "crease {e}: {t}");
                    assert_eq!(u, 0.0, "crease {e} held off until {t} s");
                }
                None => {
                    assert_eq!(hinge.release_time, 0.0);
                    assert!(
                        u != 0.0 || !scene_path.contains("cube"),
                        "crease {e} ramps from the start"
                    );
                }
            }
        }
        assert_eq!(
            ctrl.iter().filter(|&&u| u == 0.0).count(),
            if scene_path.contains("cube") { 4 } else { ctrl.len() },
            "{scene_path}: the front holds four creases back; the Miura's steps have ctrl 0"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The bridge, all four hinges released at once (drag on): MuJoCo's RK4 at 10 ns steps puts
/// plate 3's corner on the substrate when nanofold does, to 2e-4 (measured 7e-5; 8e-6 at
/// 1 ns), and the fold angles then agree. Also for the thesis's reading of the bridge (at
/// 1 ns: 2.5e-5), whose
/// stated moments break the triangle inequality that MuJoCo asks of a body: the export
/// raises I_yy, which motion about x does not feel, and says so in the model.
#[test]
fn mujoco_runs_the_exported_bridge_to_nanofolds_first_contact() {
    let Some(python) = python() else { return };
    let dir = temp_dir("bridge");
    // Bundled, plate 3's free edge lands; in the thesis's reading the crease between plates
    // 2 and 3 lands first, and either plate holding it names the contact.
    // The thesis's last plate turns ten times faster: 1 ns steps there (17 s).
    for (scene, bodies, timestep) in [
        ("patterns/bridge_step.scene.json", &["plate_3"][..], 1e-8),
        (
            "patterns/thesis/bridge_thesis_reading.scene.json",
            &["plate_2", "plate_3"][..],
            1e-9,
        ),
    ] {
        let model = dir.join("bridge.xml");
        let mjcf = export(Path::new(scene), timestep, &model);
        assert_eq!(
            mjcf.contains("I_yy raised"),
            scene.contains("thesis"),
            "{scene}: the triangle-inequality note"
        );
        // One output folder per scene: a folder holds one input's results.
        let stem = Path::new(scene).file_stem().unwrap().to_string_lossy().to_string();
        let reference = simulate_scene(Path::new(scene), &dir.join(&stem));
        let t_nanofold = reference["collision"]["time_s"].as_f64().unwrap() * 1e6;
        assert_eq!(reference["collision"]["pair"][0], "plate 3");
        let result = run_mujoco(&python, &model, 1.05 * t_nanofold);
        let first = &result["first_contact"];
        let t_mujoco = first["time_us"].as_f64().expect("MuJoCo reached a contact");
        let body = first["pair"][1].as_str().unwrap_or_default();
        assert!(bodies.contains(&body), "{scene}: {result}");
        assert!(
            (t_mujoco / t_nanofold - 1.0).abs() < 2e-4,
            "{scene}: MuJoCo {t_mujoco} µs, nanofold {t_nanofold} µs"
        );
        // The angles at each one's own contact: MuJoCo's carried back from the end of its
        // last step along its velocities. The two contact times differ by Δt (above), so an
        // angle turning at θ̇ may differ by |θ̇| Δt besides the trajectories' own 2e-3 rad:
        // the last plate of the thesis's reading turns at 1.5e6 rad/s, 1e-2 rad in 7 ns.
        let lag = (result["final_time_us"].as_f64().unwrap() - t_mujoco) * 1e-6;
        let event_gap = (t_mujoco - t_nanofold).abs() * 1e-6;
        let response: Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join(&stem).join("response.json")).unwrap()).unwrap();
        let rates = response["velocities_rad_s"]
            .as_array()
            .unwrap()
            .last()
            .unwrap()
            .as_array()
            .unwrap();
        let final_mujoco = result["final_qpos"].as_array().unwrap();
        let velocities = result["final_qvel"].as_array().unwrap();
        let final_nanofold = reference["final_angles_rad"].as_array().unwrap();
        for (((a, v), b), rate) in final_mujoco.iter().zip(velocities).zip(final_nanofold).zip(rates) {
            let at_contact = a.as_f64().unwrap() - v.as_f64().unwrap() * lag;
            let bound = 2e-3 + rate.as_f64().unwrap().abs() * event_gap;
            assert!(
                (at_contact - b.as_f64().unwrap()).abs() < bound,
                "{scene}: MuJoCo {at_contact}, nanofold {b} (bound {bound:e})"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The corner cube's step 1 (a closed loop, crease 1 locked, drag on), exported as shipped:
/// MuJoCo starts 1° along the branch (the flat start is a branch point), so nanofold runs the
/// same scene from 1° with the exact closure for the reference. RK4 at 10 ns, connect
/// equalities: the flap halves close (crease 0 at 180°) together to 1e-4 (measured 7e-6), and
/// the loop stays closed to 10 nm.
#[test]
fn mujoco_runs_the_exported_corner_cube_to_nanofolds_first_contact() {
    let Some(python) = python() else { return };
    let dir = temp_dir("corner-cube");
    let model = dir.join("corner_cube_step1.xml");
    let mjcf = export(Path::new("patterns/corner_cube_step1.scene.json"), 1e-8, &model);
    assert!(mjcf.contains("<connect") && mjcf.contains("lock_crease_1"));
    let mut scene: Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/corner_cube_step1.scene.json").unwrap()).unwrap();
    scene["start_angle_deg"] = 1.0.into();
    scene["constraint"] = serde_json::json!({ "source": "exact" });
    scene["pattern"] = std::fs::canonicalize("patterns/corner_cube_plates.fold")
        .unwrap()
        .display()
        .to_string()
        .into();
    let variant = dir.join("corner_cube_step1_from_1deg.scene.json");
    std::fs::write(&variant, scene.to_string()).unwrap();
    let reference = simulate_scene(&variant, &dir.join("sim"));
    let t_nanofold = reference["collision"]["time_s"].as_f64().unwrap() * 1e6;
    let result = run_mujoco(&python, &model, 1.2 * t_nanofold);
    let first = &result["first_contact"];
    let t_mujoco = first["time_us"].as_f64().expect("MuJoCo reached a contact");
    assert_eq!(first["pair"][0], "crease_0", "{result}");
    assert!(
        (t_mujoco / t_nanofold - 1.0).abs() < 1e-4,
        "MuJoCo {t_mujoco} µs, nanofold {t_nanofold} µs"
    );
    // MuJoCo's equalities are soft (relaxing over two steps): the loop stays closed to 10 nm,
    // 3e-5 of a 300 µm face (measured 2.3 nm at 10 ns steps).
    assert!(result["max_equality_violation"].as_f64().unwrap() < 1e-2, "{result}");
    // Closed instead by the fitted quartics (`--closure poly`): the keyframe lies on them, the
    // equalities hold to 1e-4 rad, and the contact comes within 5e-3 (measured 1.3e-3 early:
    // the quartics are 1.7e-3 rad off the closure, and the cut crease has no spring).
    let poly_model = dir.join("corner_cube_step1_poly.xml");
    let out = nanofold()
        .args([
            "export",
            "mujoco",
            "patterns/corner_cube_step1.scene.json",
            "--closure",
            "poly",
            "--timestep",
            "1e-8",
            "--out",
        ])
        .arg(&poly_model)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mjcf = std::fs::read_to_string(&poly_model).unwrap();
    assert!(mjcf.contains("curve_crease_3") && !mjcf.contains("<connect"));
    let poly = run_mujoco(&python, &poly_model, 1.2 * t_nanofold);
    let t_poly = poly["first_contact"]["time_us"]
        .as_f64()
        .expect("MuJoCo reached a contact");
    assert!(
        (t_poly / t_nanofold - 1.0).abs() < 5e-3,
        "poly: MuJoCo {t_poly} µs, nanofold {t_nanofold} µs"
    );
    assert!(poly["max_equality_violation"].as_f64().unwrap() < 1e-4, "{poly}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A ramp scene's actuators: MuJoCo's integrator activation is the drive angle θ_drive(t)
/// nanofold's forcing gives (the keyframe sets the rate), the actuator's force is K θ_drive,
/// and the activation stops at the target. Checked in the real client after 20 µs (the
/// bridge's ramp lasts 21 minutes, too long to integrate at 10 ns steps), and with a fast
/// rate for the clamp.
#[test]
fn mujoco_ramps_the_exported_stress_torques_as_nanofold_drives_them() {
    let Some(python) = python() else { return };
    let dir = temp_dir("ramp");
    let model = dir.join("bridge_ramp.xml");
    export(Path::new("patterns/bridge_ramp.scene.json"), 1e-8, &model);
    let scene = nanofold::read::load_scene(Path::new("patterns/bridge_ramp.scene.json"))
        .unwrap()
        .build()
        .unwrap();
    let chain = scene.strip().unwrap();
    let script = "import json, sys, mujoco\n\
        m = mujoco.MjModel.from_xml_path(sys.argv[1]); d = mujoco.MjData(m)\n\
        mujoco.mj_resetDataKeyframe(m, d, 0)\n\
        for _ in range(2000): mujoco.mj_step(m, d)\n\
        out = {'time_us': d.time, 'act': list(d.act), 'force': list(d.actuator_force)}\n\
        mujoco.mj_resetDataKeyframe(m, d, 0); d.ctrl[:] = 1.0\n\
        for _ in range(300): mujoco.mj_step(m, d)\n\
        out['clamped'] = list(d.act)\n\
        print(json.dumps(out))";
    let out = Command::new(&python)
        .arg("-c")
        .arg(script)
        .arg(&model)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let result: Value = serde_json::from_slice(&out.stdout).unwrap();
    let t = result["time_us"].as_f64().unwrap() * 1e-6;
    for (i, joint) in chain.model.joints().iter().enumerate() {
        let expected = chain.forcing.drive_angle(i, t);
        let act = result["act"][i].as_f64().unwrap();
        assert!((act / expected - 1.0).abs() < 1e-9, "hinge {i}: {act} vs {expected}");
        let force = result["force"][i].as_f64().unwrap() * 1e-12;
        assert!(
            (force / (joint.stiffness * expected) - 1.0).abs() < 1e-9,
            "hinge {i}: force {force}"
        );
        let clamped = result["clamped"][i].as_f64().unwrap();
        assert!(
            (clamped - chain.forcing.hinges[i].target).abs() < 1e-12,
            "hinge {i}: {clamped}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// nanofold's final angles by crease name beside MuJoCo's by joint name: the largest gap, rad.
fn largest_angle_gap(mujoco: &Value, nanofold: &Value) -> f64 {
    let names: Vec<String> = nanofold["crease_edges"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| format!("crease_{}", e.as_u64().unwrap()))
        .collect();
    let joints = mujoco["joint_names"].as_array().unwrap();
    assert_eq!(joints.len(), names.len(), "one MuJoCo joint per crease");
    joints
        .iter()
        .zip(mujoco["final_qpos"].as_array().unwrap())
        .map(|(joint, angle)| {
            let c = names.iter().position(|n| n == joint.as_str().unwrap()).unwrap();
            (angle.as_f64().unwrap() - nanofold["final_angles_rad"][c].as_f64().unwrap()).abs()
        })
        .fold(0.0, f64::max)
}

/// A scene variant of the Miura sheet in `dir`: `pattern` (under patterns/many), run to `t_end_s`.
fn miura_variant(dir: &Path, pattern: &str, t_end_s: f64) -> PathBuf {
    let mut scene: Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/devices/miura_sheet.scene.json").unwrap()).unwrap();
    scene["pattern"] = std::fs::canonicalize(Path::new("patterns/many").join(pattern))
        .unwrap()
        .display()
        .to_string()
        .into();
    scene["time"]["t_end_s"] = t_end_s.into();
    let path = dir.join(pattern.replace(".fold", ".scene.json"));
    std::fs::write(&path, scene.to_string()).unwrap();
    path
}

/// MuJoCo's run of the exported `pattern` variant for about `t_us` µs at `timestep`, and
/// nanofold's run of the same scene to the time MuJoCo's last step ended at.
fn miura_runs(python: &Path, dir: &Path, pattern: &str, t_us: f64, timestep: f64) -> (String, Value, Value) {
    let scene = miura_variant(dir, pattern, t_us * 1e-6);
    let model = dir.join(pattern.replace(".fold", ".xml"));
    let mjcf = export(&scene, timestep, &model);
    let result = run_mujoco(python, &model, t_us);
    let scene = miura_variant(dir, pattern, result["final_time_us"].as_f64().unwrap() * 1e-6);
    let reference = simulate_scene(&scene, &dir.join(pattern.replace(".fold", "")));
    (mjcf, result, reference)
}

/// A network of many loops in the real client: the 4 × 4 Miura sheet, 16 panels on 24 creases
/// (9 creases off the spanning tree, each a light body held by three connect equalities),
/// released folded with its step torques and drag. After 20 µs (1.4 periods) MuJoCo's RK4 at
/// 10 ns has every crease within 1e-6 rad of nanofold's (measured 2.5e-8) and its equalities
/// hold to 1e-5 µm (measured 6e-7). From flat, the keyframe is nanofold's state where it leaves
/// the branch point (angles, rates, time): at 1 ns steps the angles agree to 1e-2 rad over
/// 5 µs (measured 4e-3, 6e-2 if the keyframe started at rest). Near flat a loop's gap is only
/// second order in a move off the branch, so MuJoCo's soft equalities let the sheet stray
/// (the gap grows to 2.5e-2 at 10 ns steps).
#[test]
fn mujoco_runs_the_exported_miura_sheet_as_nanofold_does() {
    let Some(python) = python() else { return };
    let dir = temp_dir("miura");
    let (mjcf, result, reference) = miura_runs(&python, &dir, "miura_4x4_folded.fold", 20.0, 1e-8);
    assert_eq!(mjcf.matches("<connect").count(), 27, "three per crease off the tree");
    assert_eq!(result["drag_bodies"], 15);
    let gap = largest_angle_gap(&result, &reference);
    assert!(gap < 1e-6, "folded: MuJoCo and nanofold differ by {gap:e} rad");
    assert!(result["max_equality_violation"].as_f64().unwrap() < 1e-5, "{result}");

    let (mjcf, result, reference) = miura_runs(&python, &dir, "miura_4x4.fold", 5.0, 1e-9);
    assert!(mjcf.contains("branch point") && mjcf.contains(" qvel=\""));
    let gap = largest_angle_gap(&result, &reference);
    assert!(gap < 1e-2, "flat: MuJoCo and nanofold differ by {gap:e} rad");
    let _ = std::fs::remove_dir_all(&dir);
}
