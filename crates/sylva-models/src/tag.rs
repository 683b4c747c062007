//! Zero-sized header fields of genome files: `"model"` and `"format"` are written and checked
//! like any field, but cost nothing in memory.

/// Declares a zero-sized type that serialises as the string `$name` and accepts only it.
macro_rules! model_tag {
    ($(#[$doc:meta])* $ty:ident, $name:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        pub struct $ty;

        impl serde::Serialize for $ty {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str($name)
            }
        }

        impl<'de> serde::Deserialize<'de> for $ty {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = <String as serde::Deserialize>::deserialize(d)?;
                if text == $name {
                    Ok($ty)
                } else {
                    Err(serde::de::Error::custom(format!(
                        "`model` must be \"{}\" here, got {text:?}",
                        $name
                    )))
                }
            }
        }
    };
}
pub(crate) use model_tag;

/// Genome file format 1: serialises as `1` and accepts only `1`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct FormatV1;

impl serde::Serialize for FormatV1 {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_u32(1)
    }
}

impl<'de> serde::Deserialize<'de> for FormatV1 {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = <i64 as serde::Deserialize>::deserialize(d)?;
        if v == 1 {
            Ok(FormatV1)
        } else {
            Err(serde::de::Error::custom(format!(
                "unsupported genome `format` {v}; this version of Sylva reads format 1"
            )))
        }
    }
}
