//! Generated crease patterns behind the door: one [`Generator`] for every family
//! `docs/model.md#pattern-generators` describes, written as FOLD the way `generate` writes it.

use crate::error::Result;
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
    pub fn build(&self) -> Result<(FoldingModel, Option<Vec<f64>>)> {
        let builder = match self {
            Generator::Miura(spec) => spec.build()?,
            Generator::SquareTwist(spec) => spec.build()?,
            Generator::Waterbomb(spec) => spec.build()?,
            Generator::BirdBase(spec) => spec.build()?,
        };
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
        let (model, state) = self.build()?;
        Ok(crease_pattern_fold(&model.pattern, state.as_deref(), &self.note()))
    }
}
