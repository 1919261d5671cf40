//! Generated crease patterns behind the door: one [`Generator`] for every family
//! `docs/model.md#pattern-generators` describes, written as FOLD the way `generate` writes it.

use crate::error::{NanofoldError, Result};
use crate::folding::FoldingModel;
use crate::pattern::generate::{BirdBaseSpec, MiuraSpec, SquareTwistSpec, WaterbombSpec};
use crate::write::folding_output::crease_pattern_fold;

/// A pattern family with its parameters (each spec validates its own fields).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Generator {
    /// Miura-ori; with a zigzag fold angle, its folded state too.
    Miura(MiuraSpec),
    /// Square twist.
    SquareTwist(SquareTwistSpec),
    /// Waterbomb tessellation.
    Waterbomb(WaterbombSpec),
    /// Bird base.
    BirdBase(BirdBaseSpec),
}

impl Generator {
    /// The pattern's sheet (validated, stars and panels found) and, for a folded Miura-ori,
    /// its state.
    /// Errors name the options (`angle_deg`, `fold_deg`, `twist_deg`, …), as the front ends
    /// give them.
    pub fn build(&self) -> Result<(FoldingModel, Option<Vec<f64>>)> {
        let builder = match self {
            Generator::Miura(spec) => spec.build(),
            Generator::SquareTwist(spec) => spec.build(),
            Generator::Waterbomb(spec) => spec.build(),
            Generator::BirdBase(spec) => spec.build(),
        }
        .map_err(by_option_name)?;
        let model = FoldingModel::new(builder.build()?)?;
        let state = match self {
            Generator::Miura(spec) if spec.zigzag_fold_angle != 0.0 => Some(model.given_fold_angles()),
            _ => None,
        };
        Ok((model, state))
    }

    /// What the pattern is, in words (the FOLD file's `file_creator` note).
    pub fn note(&self) -> String {
        let text = match self {
            Generator::Miura(s) => format!(
                "Miura-ori {} x {}, angle {} deg, width {}, slant {}{}",
                s.rows,
                s.cols,
                s.sector_angle.to_degrees(),
                s.width,
                s.slant,
                if s.zigzag_fold_angle != 0.0 {
                    format!(", zigzag creases at {} deg", s.zigzag_fold_angle.to_degrees())
                } else {
                    String::new()
                }
            ),
            Generator::SquareTwist(s) => format!(
                "square twist, side {}, sheet half-side {}, twist {} deg, {} assignment",
                s.side,
                s.half_sheet,
                s.twist.to_degrees(),
                if s.flip_pleats { "pleats flipped" } else { "classic" }
            ),
            Generator::Waterbomb(s) => format!(
                "waterbomb tessellation {} x {}, row height {}",
                s.rows, s.cols, s.row_height
            ),
            Generator::BirdBase(s) => format!("bird base, half side {}", s.half_side),
        };
        format!("{text}; written by nanofold generate")
    }

    /// The pattern as the FOLD object `nanofold generate` writes.
    pub fn to_fold(&self) -> Result<serde_json::Value> {
        Ok(self.generate()?.fold)
    }

    /// The pattern as `nanofold generate` writes it, with what it says of it.
    pub fn generate(&self) -> Result<Generated> {
        let (model, state) = self.build()?;
        Ok(Generated {
            name: model.pattern.name.clone(),
            vertices: model.pattern.vertices.len(),
            creases: model.crease_count(),
            interior_vertices: model.stars.len(),
            panels: model.pattern.panel_count,
            folded: state.is_some(),
            fold: crease_pattern_fold(&model.pattern, state.as_deref(), &self.note()),
        })
    }
}

/// A generated crease pattern: its FOLD object and its counts.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The pattern's name.
    pub name: String,
    /// Vertices of the sheet.
    pub vertices: usize,
    /// Creases.
    pub creases: usize,
    /// Interior vertices.
    pub interior_vertices: usize,
    /// Panels.
    pub panels: usize,
    /// Whether it carries a folded state (a folded Miura-ori).
    pub folded: bool,
    /// The FOLD object.
    pub fold: serde_json::Value,
}

/// A generator spec's error under the option that sets the field (the specs hold radians
/// under the geometry's names; the options take degrees under `_deg` names).
fn by_option_name(error: NanofoldError) -> NanofoldError {
    match error {
        NanofoldError::InvalidField { field, value, reason } => {
            let field = match field.as_str() {
                "sector_angle" => "angle_deg".to_string(),
                "zigzag_fold_angle" => "fold_deg".to_string(),
                "twist" => "twist_deg".to_string(),
                _ => field,
            };
            NanofoldError::InvalidField { field, value, reason }
        }
        other => other,
    }
}

/// A Miura-ori's options as the front ends name them (`generate miura --rows …`).
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
struct MiuraOptions {
    rows: usize,
    cols: usize,
    angle_deg: f64,
    width: f64,
    slant: f64,
    fold_deg: f64,
}

impl Default for MiuraOptions {
    fn default() -> Self {
        let d = MiuraSpec::default();
        MiuraOptions {
            rows: d.rows,
            cols: d.cols,
            angle_deg: d.sector_angle.to_degrees(),
            width: d.width,
            slant: d.slant,
            fold_deg: 0.0,
        }
    }
}

/// A square twist's options.
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
struct SquareTwistOptions {
    side: f64,
    half_sheet: f64,
    twist_deg: f64,
    flip_pleats: bool,
}

impl Default for SquareTwistOptions {
    fn default() -> Self {
        let d = SquareTwistSpec::default();
        SquareTwistOptions {
            side: d.side,
            half_sheet: d.half_sheet,
            twist_deg: d.twist.to_degrees(),
            flip_pleats: d.flip_pleats,
        }
    }
}

/// A waterbomb tessellation's options.
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
struct WaterbombOptions {
    rows: usize,
    cols: usize,
    row_height: f64,
}

impl Default for WaterbombOptions {
    fn default() -> Self {
        let d = WaterbombSpec::default();
        WaterbombOptions {
            rows: d.rows,
            cols: d.cols,
            row_height: d.row_height,
        }
    }
}

/// A bird base's options.
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
struct BirdBaseOptions {
    half_side: f64,
}

impl Default for BirdBaseOptions {
    fn default() -> Self {
        BirdBaseOptions {
            half_side: BirdBaseSpec::default().half_side,
        }
    }
}

impl Generator {
    /// A family by its name (`miura`, `square_twist`, `waterbomb`, `bird_base`) with its
    /// options by the front ends' names (lengths in the sheet's units, angles in degrees:
    /// `angle_deg`, `fold_deg`, `twist_deg`); unknown names are refused by name.
    pub fn from_options(family: &str, options: &serde_json::Value) -> Result<Generator> {
        use super::options::options_from_json;
        Ok(match family {
            "miura" => {
                let o: MiuraOptions = options_from_json(options)?;
                Generator::Miura(MiuraSpec {
                    rows: o.rows,
                    cols: o.cols,
                    sector_angle: o.angle_deg.to_radians(),
                    width: o.width,
                    slant: o.slant,
                    zigzag_fold_angle: o.fold_deg.to_radians(),
                })
            }
            "square_twist" | "square-twist" => {
                let o: SquareTwistOptions = options_from_json(options)?;
                Generator::SquareTwist(SquareTwistSpec {
                    side: o.side,
                    half_sheet: o.half_sheet,
                    twist: o.twist_deg.to_radians(),
                    flip_pleats: o.flip_pleats,
                })
            }
            "waterbomb" => {
                let o: WaterbombOptions = options_from_json(options)?;
                Generator::Waterbomb(WaterbombSpec {
                    rows: o.rows,
                    cols: o.cols,
                    row_height: o.row_height,
                })
            }
            "bird_base" | "bird-base" => {
                let o: BirdBaseOptions = options_from_json(options)?;
                Generator::BirdBase(BirdBaseSpec { half_side: o.half_side })
            }
            other => {
                return Err(NanofoldError::invalid(
                    "kind",
                    other,
                    "expected \"miura\", \"square_twist\", \"waterbomb\" or \"bird_base\"",
                ))
            }
        })
    }
}
