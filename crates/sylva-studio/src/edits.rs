//! Field edits: setting a genome's values by path, checked against its model's schema
//! first (so a slider's value out of range is named with the field, the range and the
//! value) and then by the model; each model's schema for the page's controls; and a sketch,
//! a picture of a plant with some fields set, recorded nowhere, which the plant panel
//! shows while a slider moves.

use axum::Json;
use axum::extract::{Path, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use serde::Deserialize;
use sylva::render::View;
use sylva::schema::Schema;
use sylva::{Genome, Registry};

use crate::Studio;
use crate::archive::PlantRow;
use crate::error::ApiError;
use crate::http::{Body, in_page_words};
use crate::plants::{PreviewSize, imported, parse_genome, parse_size, plant_row, preview_glb};
use crate::pruning::{grow_shown, pruned_to};

/// One field's new value, by its path (`branches[0].waves`, as `GET /api/plants/{id}` lists).
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct FieldEdit {
    path: String,
    value: serde_json::Value,
}

/// `plant`'s genome with `fields` set. A value outside its field's range is refused by the
/// schema, a value the genome refuses otherwise by the model; either is named as the
/// edit's (`fields[1].value`) with the field's path and what it takes, found by setting the
/// edits one at a time: the genome's own message points into JSON text the person never saw.
pub fn edited(
    registry: &Registry,
    plant: &PlantRow,
    fields: &[FieldEdit],
) -> Result<Genome, ApiError> {
    let mut value: serde_json::Value = serde_json::from_str(&plant.genome)
        .map_err(|e| ApiError::internal(format!("plant {}'s stored genome: {e}", plant.id)))?;
    let schema = registry.get(&plant.model).map(|entry| entry.schema());
    for (i, edit) in fields.iter().enumerate() {
        if let Some(schema) = schema.as_ref().filter(|s| s.field(&edit.path).is_some()) {
            schema
                .check(&edit.path, &edit.value)
                .map_err(|e| ApiError::unprocessable(format!("fields[{i}].value"), e))?;
        }
        set_field(&mut value, &edit.path, edit.value.clone()).ok_or_else(|| {
            ApiError::bad(
                format!("fields[{i}].path"),
                format!("the genome has no field {:?}", edit.path),
            )
        })?;
        if let Err(e) = registry.parse_genome(&value.to_string()) {
            return Err(ApiError::unprocessable(
                format!("fields[{i}].value"),
                in_page_words(&edit.path, &e.message),
            ));
        }
    }
    parse_genome(registry, &value.to_string(), "fields")
}

/// The value at `path` (`a.b[2].c`) in a genome's JSON, if the path is there and holds one
/// value (a number, a name, or a list of numbers such as an axis), not a part of the genome
/// made of others.
fn field_mut<'a>(
    genome: &'a mut serde_json::Value,
    path: &str,
) -> Option<&'a mut serde_json::Value> {
    let mut at = genome;
    for part in path.split('.') {
        let (name, indices) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if !name.is_empty() {
            at = at.get_mut(name)?;
        }
        for index in indices.split(['[', ']']).filter(|s| !s.is_empty()) {
            at = at.get_mut(index.parse::<usize>().ok()?)?;
        }
    }
    let composite = |v: &serde_json::Value| v.is_object() || v.is_array();
    match &*at {
        serde_json::Value::Object(_) => None,
        serde_json::Value::Array(items) if items.iter().any(composite) => None,
        _ => Some(at),
    }
}

/// Sets the value at `path` in a genome's JSON ([`field_mut`]'s paths).
fn set_field(genome: &mut serde_json::Value, path: &str, value: serde_json::Value) -> Option<()> {
    *field_mut(genome, path)? = value;
    Some(())
}

/// Most fields a breeding step keeps locked.
pub const MAX_LOCKED: usize = 4096;

/// `child` with the fields at `paths` as `parent` has them: fields a person locked keep
/// their values through mutation and crossing. A path one of them lacks (a list item the
/// child no longer has, say) is left as the operator made it; a child the locked values
/// make unreadable is refused, naming `locked`.
pub fn locked(child: Genome, parent: &Genome, paths: &[String]) -> Result<Genome, ApiError> {
    if paths.is_empty() {
        return Ok(child);
    }
    let mut from = parent.to_value();
    let mut value = child.to_value();
    for path in paths {
        if let Some(kept) = field_mut(&mut from, path) {
            set_field(&mut value, path, kept.clone());
        }
    }
    child
        .reparse(&value.to_string())
        .map_err(|e| ApiError::unprocessable("locked", in_page_words("locked", &e.message)))
}

/// Checks a step's locked paths: at most [`MAX_LOCKED`], each a path of at most 256 bytes.
pub fn check_locked(paths: &[String]) -> Result<(), ApiError> {
    if paths.len() > MAX_LOCKED {
        return Err(ApiError::bad(
            "locked",
            format!("at most {MAX_LOCKED} fields, got {}", paths.len()),
        ));
    }
    match paths.iter().position(|p| p.is_empty() || p.len() > 256) {
        Some(i) => Err(ApiError::bad(
            format!("locked[{i}]"),
            "expected a field's path (1 to 256 bytes), as the plant panel lists them",
        )),
        None => Ok(()),
    }
}

/// `GET /api/schema/{model}`: the model's genome field by field, for the plant panel's
/// controls.
pub(crate) async fn schema(
    State(studio): State<Studio>,
    Path(model): Path<String>,
) -> Result<Json<Schema>, ApiError> {
    let entry = studio
        .registry
        .get(&model)
        .ok_or_else(|| ApiError::not_found(format!("model {model:?}")))?;
    Ok(Json(entry.schema()))
}

/// `POST /api/plants/{id}/sketch.png`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct SketchRequest {
    fields: Vec<FieldEdit>,
    /// `WxH`, 16 to 2048 a side [default 320x320].
    size: Option<String>,
}

/// `POST /api/plants/{id}/sketch.png`: a picture of the plant with `fields` set, grown as
/// the views show it and drawn from a preview's detail; nothing is recorded or kept. The
/// plant panel asks for one as a slider moves, and records the edit when it is let go.
pub(crate) async fn sketch(
    State(studio): State<Studio>,
    Path(id): Path<i64>,
    Body(request): Body<SketchRequest>,
) -> Result<Response, ApiError> {
    let size = match request.size.as_deref() {
        None => (320, 320),
        Some(s) => parse_size(s)?,
    };
    let png = tokio::task::spawn_blocking(move || -> Result<Vec<u8>, ApiError> {
        let row = plant_row(&studio, id)?;
        let genome = edited(&studio.registry, &row, &request.fields)?;
        let plant = grow_shown(&genome, row.seed, pruned_to(&studio, &row)?)?;
        let glb = preview_glb(
            &genome,
            row.seed,
            &plant,
            PreviewSize::of(size.0.max(size.1)),
        )?;
        let scene = imported(&glb)?;
        sylva::assets::picture(&scene.scene(), View::Iso, size).map_err(ApiError::internal)
    })
    .await??;
    Ok(([(header::CONTENT_TYPE, "image/png")], png).into_response())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn locked_fields_keep_the_parents_values_and_missing_ones_are_left() {
        let registry = Registry::standard();
        let parse = |text: &str| registry.parse_genome(text).unwrap();
        let oak = include_str!("../../../examples/bintree/oak.json");
        let parent = parse(oak);
        let mut other = parent.to_value();
        other["depth"] = json!(4);
        other["length"] = json!(2.5);
        let child = parse(&other.to_string());
        let paths = ["depth".to_owned(), "branches[3].waves".to_owned()];
        let kept = locked(child, &parent, &paths).unwrap().to_value();
        assert_eq!(kept["depth"], parent.to_value()["depth"]);
        assert_eq!(
            kept["length"],
            json!(2.5),
            "an unlocked field stays as the operator made it"
        );
        assert!(check_locked(&vec!["x".to_owned(); MAX_LOCKED + 1]).is_err());
        assert!(check_locked(&[String::new()]).is_err());
    }

    #[test]
    fn fields_are_set_by_path_and_only_single_values() {
        let mut g =
            json!({"a": {"b": [1, {"c": 2}]}, "axis": [0, 1, 0], "seed": 18446744073709551615u64});
        assert!(set_field(&mut g, "a.b[1].c", json!(5)).is_some());
        assert!(set_field(&mut g, "a.b[0]", json!(7)).is_some());
        assert_eq!(g["a"]["b"], json!([7, {"c": 5}]));
        assert!(set_field(&mut g, "axis", json!([1, 0, 0])).is_some());
        assert_eq!(g["axis"], json!([1, 0, 0]));
        assert!(set_field(&mut g, "a.b", json!(0)).is_none());
        assert!(set_field(&mut g, "a", json!(0)).is_none());
        assert!(set_field(&mut g, "a.x", json!(0)).is_none());
        assert!(set_field(&mut g, "a.b[9]", json!(0)).is_none());
        assert_eq!(g["seed"].as_u64(), Some(u64::MAX));
    }
}
