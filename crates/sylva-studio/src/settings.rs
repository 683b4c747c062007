//! Model settings a page's form asks for, built as the library's typed settings
//! ([`sylva::models`]) and read with their own checks: every range a config file's reader
//! holds a value to is held by the type's reader, so a form's value goes through it too,
//! and an error names the request's field, as a 422 (well-formed, but not settings Sylva
//! can use).

use serde::Serialize;
use serde::de::DeserializeOwned;
use sylva::FieldError;

use crate::error::ApiError;
use crate::http::join;

/// A typed value read from part of a request, its fields named under `at` (that part's
/// JSON path in the request).
pub fn read<T: DeserializeOwned>(value: serde_json::Value, at: &str) -> Result<T, ApiError> {
    checked(value).map_err(|e| ApiError::unprocessable(join(at, &e.field), e.message))
}

/// `base` with the fields a request's object `changes` sets, read back through `T`'s
/// checks; errors name the field under `at`. For a form that names only the fields it
/// changes from defaults of the studio's own (not the type's).
pub fn overlay<T: Serialize + DeserializeOwned>(
    base: &T,
    changes: &serde_json::Map<String, serde_json::Value>,
    at: &str,
) -> Result<T, ApiError> {
    let mut value = serde_json::to_value(base).map_err(ApiError::internal)?;
    let serde_json::Value::Object(fields) = &mut value else {
        return Err(ApiError::internal("settings that are not a table"));
    };
    fields.extend(changes.iter().map(|(k, v)| (k.clone(), v.clone())));
    read(value, at)
}

/// A value built in code (`built`, such as a grid's config from a painted grid) read as a
/// `T`, the type that checks it; errors name the field under `at`.
pub fn checked_as<T: DeserializeOwned>(built: &impl Serialize, at: &str) -> Result<T, ApiError> {
    read(serde_json::to_value(built).map_err(ApiError::internal)?, at)
}

/// Reads `value` as a `T`, naming the field of an error.
fn checked<T: DeserializeOwned>(value: serde_json::Value) -> Result<T, FieldError> {
    let sent = value.clone();
    serde_path_to_error::deserialize(value).map_err(|e| FieldError::of(&e, &sent))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sylva::core::glam::DVec3;
    use sylva::models::{DensityGrid, GridConfig, PoncinWeights, TargetShape};

    #[test]
    fn a_form_value_is_held_to_the_type_s_ranges_and_named() {
        let e = read::<TargetShape>(
            serde_json::json!({"shape": "sphere", "radius": -1}),
            "design.target",
        )
        .unwrap_err();
        assert_eq!(e.status, 422);
        assert_eq!(e.field, "design.target.radius", "{e}");
        let shape: TargetShape =
            read(serde_json::json!({"shape": "sphere", "radius": 80}), "t").unwrap();
        assert!(matches!(shape, TargetShape::Sphere { radius: 80.0, .. }));
    }

    #[test]
    fn an_overlay_keeps_the_studio_s_defaults_and_checks_the_changes() {
        let base = PoncinWeights {
            dist: 200.0,
            ..PoncinWeights::TEXT
        };
        let changes = serde_json::json!({"pos": 9});
        let weights = overlay(&base, changes.as_object().unwrap(), "w").unwrap();
        assert_eq!((weights.pos, weights.dist), (9.0, 200.0));
        let bad = serde_json::json!({"num": -2});
        let e = overlay(&base, bad.as_object().unwrap(), "design.weights").unwrap_err();
        assert_eq!(e.field, "design.weights.num", "{e}");
        let unknown = serde_json::json!({"colour": 1});
        let e = overlay(&base, unknown.as_object().unwrap(), "design.weights").unwrap_err();
        assert_eq!(e.field, "design.weights.colour", "{e}");
    }

    #[test]
    fn a_value_built_in_code_is_held_to_the_checks_of_the_type_it_becomes() {
        let flat = GridConfig {
            min: DVec3::ZERO,
            max: DVec3::new(1.0, 0.0, 1.0),
            divisions: [2, 2, 2],
            weight: 0.0,
            target: 15,
            boxes: Vec::new(),
            cells: Vec::new(),
        };
        let e = checked_as::<DensityGrid>(&flat, "design.grid").unwrap_err();
        assert_eq!(e.field, "design.grid.max", "{e}");
        let far = GridConfig {
            min: DVec3::new(-2e6, 0.0, 0.0),
            ..flat.clone()
        };
        let e = checked_as::<DensityGrid>(&far, "design.grid").unwrap_err();
        assert_eq!(e.field, "design.grid.min", "{e}");
        let grid = GridConfig {
            max: DVec3::ONE,
            ..flat
        };
        let checked: DensityGrid = checked_as(&grid, "design.grid").unwrap();
        assert_eq!(checked.config(), &grid);
    }
}
