//! Model choices: a closed set of names written in the model file (`churning = "changenet"`,
//! `kind = "ravigneaux"`), each an enum read once with its section. A name outside the set is
//! reported at its key path with every allowed name (`must be one of: …`); a value that is not a
//! string, with its type (`invalid type: integer `1`, expected a string`).
//!
//! [`choice!`] gives an enum its names: the [`Choice`] table, and serde reading and writing by
//! name.

use serde::{de::Error as _, Deserialize, Deserializer};

/// An enum written in the model file by name.
pub trait Choice: Copy + 'static {
    /// Every variant with its name, in the order messages list them.
    const NAMES: &'static [(&'static str, Self)];

    /// The name of this variant.
    fn name(self) -> &'static str;

    /// The variant named `s`.
    fn from_name(s: &str) -> Option<Self> {
        Self::NAMES.iter().find(|(n, _)| *n == s).map(|&(_, v)| v)
    }

    /// What a bad name is told: `must be one of: a, b, c`.
    fn allowed() -> String {
        let names: Vec<&str> = Self::NAMES.iter().map(|(n, _)| *n).collect();
        format!("must be one of: {}", names.join(", "))
    }
}

/// Read a choice: a string, one of the names.
pub fn deserialize<'de, D: Deserializer<'de>, T: Choice>(d: D) -> Result<T, D::Error> {
    let s = String::deserialize(d)?;
    T::from_name(&s).ok_or_else(|| D::Error::custom(T::allowed()))
}

/// Read an optional choice (`#[serde(default, deserialize_with = "choice::optional")]`), for
/// enums whose serde reading is defined elsewhere.
pub fn optional<'de, D: Deserializer<'de>, T: Choice>(d: D) -> Result<Option<T>, D::Error> {
    deserialize(d).map(Some)
}

/// `choice!(Type { Variant = "name", ... })`: the [`Choice`] table of `Type` (every variant must
/// be listed: the name match is exhaustive) and its serde `Deserialize` and `Serialize` by name.
/// `choice!(@names Type { ... })`: the table only.
macro_rules! choice {
    (@names $t:ty { $($v:ident = $n:literal),+ $(,)? }) => {
        impl $crate::model::choice::Choice for $t {
            const NAMES: &'static [(&'static str, Self)] = &[$(($n, <$t>::$v)),+];

            fn name(self) -> &'static str {
                match self {
                    $(<$t>::$v => $n,)+
                }
            }
        }
    };
    ($t:ty { $($v:ident = $n:literal),+ $(,)? }) => {
        choice!(@names $t { $($v = $n),+ });

        impl<'de> serde::Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                $crate::model::choice::deserialize(d)
            }
        }

        impl serde::Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str($crate::model::choice::Choice::name(*self))
            }
        }
    };
}
pub(crate) use choice;

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Colour {
        Red,
        DarkBlue,
    }
    choice!(Colour {
        Red = "red",
        DarkBlue = "dark_blue",
    });

    #[test]
    fn names_round_trip_and_a_bad_name_lists_the_allowed_ones() {
        for &(n, v) in Colour::NAMES {
            assert_eq!(v.name(), n);
            assert_eq!(Colour::from_name(n), Some(v));
            let back: Colour = serde_json::from_value(serde_json::to_value(v).unwrap()).unwrap();
            assert_eq!(back, v);
        }
        let e = serde_json::from_str::<Colour>("\"green\"")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("must be one of: red, dark_blue"), "{e}");
        let e = serde_json::from_str::<Colour>("1").unwrap_err().to_string();
        assert!(
            e.starts_with("invalid type: integer `1`, expected a string"),
            "{e}"
        );
    }
}
