//! How precisely a solid's coordinates are known, and the tolerances that follow from it
//! (`docs/model.md#precision-of-a-solid`): a file written to 6 decimals or as float32 has
//! vertices off their true places by up to half its last digit, and every test of a solid
//! built from it (planar faces, coincident vertices, symmetries) allows that much.

use serde::Serialize;

/// Where a bound on the coordinates' rounding comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PrecisionSource {
    /// Computed in double precision (a generated solid, or a file of integers).
    Exact,
    /// Written in text with this many significant digits at most.
    Digits,
    /// Stored as 32-bit floats (binary STL, PLY `float`).
    Float32,
    /// Stored as 64-bit floats (PLY `double`) or written with every digit of one.
    Float64,
}

/// A bound on how far each coordinate may be from the value it stands for.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Precision {
    /// The largest rounding error of a coordinate, in the solid's units.
    pub rounding: f64,
    /// What sets it.
    pub source: PrecisionSource,
    /// For `Digits`: the significant digits the file writes.
    pub significant_digits: u32,
}

impl Precision {
    /// Coordinates known to double precision (the arithmetic's own rounding is the floor
    /// every tolerance keeps).
    pub const EXACT: Precision = Precision {
        rounding: 0.0,
        source: PrecisionSource::Exact,
        significant_digits: 17,
    };

    /// In words, for reports: "6 significant digits (rounding ≤ 5e-7)".
    pub fn describe(&self) -> String {
        match self.source {
            PrecisionSource::Exact => "exact (double precision)".to_string(),
            PrecisionSource::Digits => format!(
                "{} significant digits (each coordinate within {:.1e})",
                self.significant_digits, self.rounding
            ),
            PrecisionSource::Float32 => format!("32-bit floats (each coordinate within {:.1e})", self.rounding),
            PrecisionSource::Float64 => format!("64-bit floats (each coordinate within {:.1e})", self.rounding),
        }
    }
}

/// Reads the precision off the numbers a file writes: each coordinate as text, or as the
/// float width it is stored in.
///
/// A writer rounds every coordinate to a fixed number of significant digits (`%g`, `%e`) or
/// of decimals (`%.6f`, which writes trailing zeros, so its largest numbers show its digits);
/// either way the coordinate with the most significant digits shows the writer's, and the
/// largest coordinate carries the largest error: half a unit in that many digits' last place.
/// A file whose every coordinate is an integer is taken as exact.
#[derive(Debug, Clone, Default)]
pub struct DigitsSeen {
    most_digits: u32,
    largest_exponent: Option<i32>,
    largest_magnitude: f64,
    fractional: bool,
    float32: bool,
    float64_storage: bool,
}

impl DigitsSeen {
    /// A coordinate as the file writes it (`-1.618034`, `1.000000e+00`, `2`).
    pub fn text(&mut self, token: &str) {
        let token = token.trim().trim_start_matches(['+', '-']);
        let (mantissa, exponent) = match token.find(['e', 'E']) {
            Some(at) => (&token[..at], token[at + 1..].parse::<i32>().unwrap_or(0)),
            None => (token, 0),
        };
        let (whole, fraction) = mantissa.split_once('.').unwrap_or((mantissa, ""));
        let digits: String = whole
            .chars()
            .chain(fraction.chars())
            .filter(char::is_ascii_digit)
            .collect();
        let leading_zeros = digits.chars().take_while(|&c| c == '0').count();
        let significant = digits.len() - leading_zeros;
        if significant == 0 {
            return; // a zero tells nothing of the digits
        }
        // The leading digit's decimal place: whole.len() − 1 − leading zeros, shifted.
        let place = whole.len() as i32 - 1 - leading_zeros as i32 + exponent;
        self.most_digits = self.most_digits.max(significant as u32);
        self.largest_exponent = Some(self.largest_exponent.map_or(place, |e| e.max(place)));
        // A fraction digit or a negative exponent that survives is a fractional value.
        let fraction_digits = fraction.trim_end_matches('0').len() as i32;
        if fraction_digits > exponent || (exponent < 0 && !digits.trim_end_matches('0').is_empty()) {
            self.fractional = true;
        }
        if let Ok(value) = token.parse::<f64>() {
            self.largest_magnitude = self.largest_magnitude.max(value.abs());
        }
    }

    /// A coordinate stored as a 64-bit float and written by its shortest decimal form (a
    /// FOLD file's JSON number).
    pub fn json_number(&mut self, value: f64) {
        self.text(&format!("{value}"));
    }

    /// A coordinate stored in binary as a 32-bit float (binary STL and PLY): the float's
    /// own rounding (its shortest decimal form says nothing of a writer's).
    pub fn binary_single(&mut self, value: f32) {
        self.float32 = true;
        self.largest_magnitude = self.largest_magnitude.max(value.abs() as f64);
        self.fractional |= value.fract() != 0.0;
    }

    /// A coordinate stored in binary as a 64-bit float.
    pub fn binary_double(&mut self, value: f64) {
        self.float64_storage = true;
        self.largest_magnitude = self.largest_magnitude.max(value.abs());
        self.fractional |= value.fract() != 0.0;
    }

    /// Coordinates written as text and then held as 32-bit floats (ASCII PLY's `float`):
    /// both roundings count.
    pub fn held_as_single(&mut self) {
        self.float32 = true;
    }

    /// The bound these coordinates carry.
    pub fn precision(&self) -> Precision {
        let storage = if self.float32 {
            Some((PrecisionSource::Float32, self.largest_magnitude * 2f64.powi(-24)))
        } else if self.float64_storage {
            Some((PrecisionSource::Float64, self.largest_magnitude * 2f64.powi(-53)))
        } else {
            None
        };
        let written = match self.largest_exponent {
            // Sixteen or more digits: every digit of a double, nothing rounded by the writer.
            Some(place) if self.fractional && self.most_digits < 16 => {
                Some(0.5 * 10f64.powi(place - self.most_digits as i32 + 1))
            }
            _ => None,
        };
        match (written, storage) {
            (Some(text), Some((source, float))) if float > text => Precision {
                rounding: float,
                source,
                significant_digits: self.most_digits,
            },
            (Some(text), _) => Precision {
                rounding: text,
                source: PrecisionSource::Digits,
                significant_digits: self.most_digits,
            },
            (None, _) if !self.fractional => Precision::EXACT,
            (None, Some((source, float))) => Precision {
                rounding: float,
                source,
                significant_digits: self.most_digits,
            },
            (None, None) => Precision {
                rounding: self.largest_magnitude * 2f64.powi(-53),
                source: PrecisionSource::Float64,
                significant_digits: self.most_digits,
            },
        }
    }
}

/// The tolerances a solid's tests use, lengths in its units: each the most that rounding
/// by `Precision::rounding` (δ per coordinate, ε = √3 δ per vertex) can produce, and never
/// below the arithmetic's own floor (a fraction of the solid's size).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Tolerances {
    /// The rounding the tolerances are from.
    pub precision: Precision,
    /// The solid's size (its largest distance from its vertex centroid).
    pub size: f64,
    /// Two vertices this close are one: 2ε (two roundings), at least 1e-12 of the size.
    pub coincident: f64,
    /// A vertex this far from its face's plane still lies on it, and faces this close to one
    /// plane are one plane: 4ε (the vertex's own rounding, the centroid's and the normal's
    /// tilt by the others'), at least 1e-9 of the size.
    pub planarity: f64,
    /// An isometry maps every vertex within this of a vertex: 4ε (both ends rounded, and
    /// the fitted map's own error), at least 1e-7 of the size.
    pub symmetry: f64,
}

impl Tolerances {
    /// The tolerances of a solid of `size` whose coordinates carry `precision`.
    pub fn new(precision: Precision, size: f64) -> Tolerances {
        let vertex = 3f64.sqrt() * precision.rounding;
        Tolerances {
            precision,
            size,
            coincident: (2.0 * vertex).max(1e-12 * size),
            planarity: (4.0 * vertex).max(1e-9 * size),
            symmetry: (4.0 * vertex).max(1e-7 * size),
        }
    }

    /// Whether the coordinates were rounded by more than the arithmetic's own floor.
    pub fn rounded(&self) -> bool {
        4.0 * 3f64.sqrt() * self.precision.rounding > 1e-9 * self.size
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn of(tokens: &[&str]) -> Precision {
        let mut seen = DigitsSeen::default();
        tokens.iter().for_each(|t| seen.text(t));
        seen.precision()
    }

    #[test]
    fn the_digits_a_writer_uses_give_the_rounding() {
        // %.6f, as Blender writes: half a millionth.
        let p = of(&["1.000000", "-0.618034", "1.618034", "0.000000"]);
        assert_eq!((p.source, p.significant_digits), (PrecisionSource::Digits, 7));
        assert!((p.rounding - 5e-7).abs() < 1e-20, "{p:?}");
        // %e with 6 decimals: its largest exponent sets the error.
        let p = of(&["1.234567e+01", "-3.000000e-05"]);
        assert!((p.rounding - 5e-6).abs() < 1e-20, "{p:?}");
        // %g drops trailing zeros: "1" says nothing, 1.61803 says 6 digits.
        let p = of(&["1", "1.61803", "0.618034"]);
        assert!((p.rounding - 5e-6).abs() < 1e-20, "{p:?}");
        // Every digit of a double: nothing rounded but the double itself.
        let p = of(&["1.618033988749895", "0.5"]);
        assert_eq!(p.source, PrecisionSource::Float64);
        assert!(p.rounding < 1e-15);
        // Integers are exact.
        assert_eq!(of(&["1", "-2", "0", "3"]), Precision::EXACT);
    }

    #[test]
    fn a_float32_carries_its_own_rounding_beside_the_writers() {
        let mut seen = DigitsSeen::default();
        for x in [1.618034f32 * 1000.0, -1.0, 0.5] {
            seen.binary_single(x);
        }
        let p = seen.precision();
        assert_eq!(p.source, PrecisionSource::Float32, "{p:?}");
        assert!((p.rounding - 1618.034 * 2f64.powi(-24)).abs() < 1e-9, "{p:?}");
        // Text rounded to 7 digits (5e-7) and then held as a float32 (1e-7): the text's.
        let mut seen = DigitsSeen::default();
        for t in ["1.618034", "-1.000000"] {
            seen.text(t);
        }
        seen.held_as_single();
        let p = seen.precision();
        assert_eq!(p.source, PrecisionSource::Digits);
        assert!((p.rounding - 5e-7).abs() < 1e-20, "{p:?}");
        // Integer floats are exact.
        let mut seen = DigitsSeen::default();
        seen.binary_single(2.0);
        assert_eq!(seen.precision(), Precision::EXACT);
    }
}
