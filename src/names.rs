//! The names reports give enum values: a variant's name is its serde name, read by a
//! serializer that stops at the variant, so the words a report prints and the JSON it writes
//! cannot disagree.

use serde::ser::{self, Impossible, Serialize};

/// An enum named in outputs by its serde names: a verdict, an engine, a stop.
pub trait Named: Serialize {
    /// The variant's name in outputs (its serde name).
    fn as_str(&self) -> &'static str {
        variant_name(self)
    }
}

/// A command's answer: a verdict named in outputs, and why.
pub trait Answer {
    /// The verdict's name in outputs.
    fn verdict_name(&self) -> &'static str;
    /// Why, in words.
    fn evidence(&self) -> &str;
}

/// The serde name of `value`'s variant (`rename_all` applied): `"not_rigid"` for
/// `NotRigid` under `snake_case`. A value that is not an enum variant has no name: that is
/// a programming error, caught by the tests of every enum that uses this.
pub fn variant_name<T: Serialize + ?Sized>(value: &T) -> &'static str {
    value
        .serialize(VariantName)
        .expect("variant_name is for enums whose variants serde names")
}

/// Why a value had no variant name.
#[derive(Debug)]
pub struct NotAVariant;

impl std::fmt::Display for NotAVariant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("not an enum variant")
    }
}

impl std::error::Error for NotAVariant {}

impl ser::Error for NotAVariant {
    fn custom<M: std::fmt::Display>(_: M) -> Self {
        NotAVariant
    }
}

/// Serializes a variant to its name; anything else is [`NotAVariant`].
struct VariantName;

/// A variant with fields: its name, the fields unread.
struct NameOf(&'static str);

impl ser::SerializeStructVariant for NameOf {
    type Ok = &'static str;
    type Error = NotAVariant;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, _: &'static str, _: &T) -> Result<(), NotAVariant> {
        Ok(())
    }
    fn end(self) -> Result<&'static str, NotAVariant> {
        Ok(self.0)
    }
}

impl ser::SerializeTupleVariant for NameOf {
    type Ok = &'static str;
    type Error = NotAVariant;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, _: &T) -> Result<(), NotAVariant> {
        Ok(())
    }
    fn end(self) -> Result<&'static str, NotAVariant> {
        Ok(self.0)
    }
}

macro_rules! not_a_variant {
    ($($method:ident($($arg:ty),*)),* $(,)?) => {
        $(fn $method(self, $(_: $arg),*) -> Result<&'static str, NotAVariant> {
            Err(NotAVariant)
        })*
    };
}

impl ser::Serializer for VariantName {
    type Ok = &'static str;
    type Error = NotAVariant;
    type SerializeSeq = Impossible<&'static str, NotAVariant>;
    type SerializeTuple = Impossible<&'static str, NotAVariant>;
    type SerializeTupleStruct = Impossible<&'static str, NotAVariant>;
    type SerializeTupleVariant = NameOf;
    type SerializeMap = Impossible<&'static str, NotAVariant>;
    type SerializeStruct = Impossible<&'static str, NotAVariant>;
    type SerializeStructVariant = NameOf;

    fn serialize_unit_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
    ) -> Result<&'static str, NotAVariant> {
        Ok(variant)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: &T,
    ) -> Result<&'static str, NotAVariant> {
        Ok(variant)
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<NameOf, NotAVariant> {
        Ok(NameOf(variant))
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<NameOf, NotAVariant> {
        Ok(NameOf(variant))
    }

    not_a_variant!(
        serialize_bool(bool),
        serialize_i8(i8),
        serialize_i16(i16),
        serialize_i32(i32),
        serialize_i64(i64),
        serialize_u8(u8),
        serialize_u16(u16),
        serialize_u32(u32),
        serialize_u64(u64),
        serialize_f32(f32),
        serialize_f64(f64),
        serialize_char(char),
        serialize_str(&str),
        serialize_bytes(&[u8]),
        serialize_none(),
        serialize_unit(),
        serialize_unit_struct(&'static str),
    );

    fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> Result<&'static str, NotAVariant> {
        Err(NotAVariant)
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: &T,
    ) -> Result<&'static str, NotAVariant> {
        Err(NotAVariant)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, NotAVariant> {
        Err(NotAVariant)
    }
    fn serialize_tuple(self, _: usize) -> Result<Self::SerializeTuple, NotAVariant> {
        Err(NotAVariant)
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Self::SerializeTupleStruct, NotAVariant> {
        Err(NotAVariant)
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, NotAVariant> {
        Err(NotAVariant)
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Self::SerializeStruct, NotAVariant> {
        Err(NotAVariant)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(serde::Serialize)]
    #[serde(rename_all = "snake_case")]
    enum Example {
        NotRigid,
        Blocked {
            _panels: [usize; 2],
        },
        #[allow(dead_code)]
        Pair(u8, u8),
        Wrapped(#[allow(dead_code)] String),
    }

    #[test]
    fn every_kind_of_variant_is_named_as_serde_names_it() {
        assert_eq!(variant_name(&Example::NotRigid), "not_rigid");
        assert_eq!(variant_name(&Example::Blocked { _panels: [1, 2] }), "blocked");
        assert_eq!(variant_name(&Example::Pair(1, 2)), "pair");
        assert_eq!(variant_name(&Example::Wrapped("x".into())), "wrapped");
        assert_eq!(serde_json::to_value(Example::NotRigid).unwrap(), "not_rigid");
        assert!(std::panic::catch_unwind(|| variant_name(&3_u8)).is_err());
    }
}
