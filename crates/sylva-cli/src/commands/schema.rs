//! `sylva schema`: every model's genome field by field, as the docs' tables or as JSON.

use sylva::{InputError, Registry};

/// Arguments of `sylva schema`.
#[derive(clap::Args)]
pub struct SchemaArgs {
    /// The model [default: every model].
    model: Option<String>,
    /// Print the schema as JSON (each field's path, group, meaning, kind, range, unit).
    #[arg(long)]
    json: bool,
}

/// The opening of docs/genomes.md, which is this command's output for every model.
const PREAMBLE: &str = "# Genomes field by field\n\n\
Every model's genome as a person sets it by hand: each field's path in a genome file, its \
group, the values it takes and what it does. The fields in bold move the plant's shape most. \
One description serves the studio, Python (`sylva.schema(\"plantmaker\")`) and this page, \
which is the output of `sylva schema` (a test keeps them the same); `sylva schema MODEL \
--json` gives one model's as JSON. A value outside its field's range is refused naming the \
field, the range and the value.\n";

pub fn run(models: &Registry, args: &SchemaArgs) -> anyhow::Result<()> {
    let entries: Vec<_> = match &args.model {
        Some(name) => vec![models.get(name).ok_or_else(|| {
            let known: Vec<_> = models.models().iter().map(|m| m.name()).collect();
            InputError::new(
                "MODEL",
                format!(
                    "no model is named {name:?}; expected one of {}",
                    known.join(", ")
                ),
            )
        })?],
        None => models.models().iter().collect(),
    };
    if args.json {
        let schemas: serde_json::Map<_, _> = entries
            .iter()
            .map(|m| (m.name().to_owned(), serde_json::json!(m.schema())))
            .collect();
        let value = match &args.model {
            Some(name) => schemas[name].clone(),
            None => serde_json::Value::Object(schemas),
        };
        println!("{value:#}");
        return Ok(());
    }
    let every = args.model.is_none();
    if every {
        print!("{PREAMBLE}");
    }
    for m in entries {
        if every {
            println!();
        }
        println!("## {} (`{}`)\n", m.title(), m.name());
        print!("{}", m.schema().markdown());
    }
    Ok(())
}
