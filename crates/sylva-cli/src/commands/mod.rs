//! The commands behind each subcommand: each reads the files it is given, calls the library,
//! writes its results and reports what it wrote.

pub mod breed;
pub mod evolve;
pub mod garden;
pub mod grow;
pub mod inspect;
pub mod matching;
pub mod render;
mod run_files;
pub mod schema;
pub mod simulate;
pub mod studio;
pub mod varieties;

use std::fmt::Display;
use std::path::Path;

use indicatif::{ProgressBar, ProgressStyle};
use sylva::core::budget::Seconds;

/// Writes a run's checkpoint file every `checkpoint_seconds` while it runs, and when it
/// ends: a run killed at any moment loses at most that much work.
pub struct Checkpoints<'a> {
    path: &'a Path,
    every: std::time::Duration,
    last: std::time::Instant,
}

impl<'a> Checkpoints<'a> {
    /// Checkpoints to `path`, every `seconds`.
    pub fn new(path: &'a Path, seconds: f64) -> Self {
        Checkpoints {
            path,
            every: std::time::Duration::from_secs_f64(seconds),
            last: std::time::Instant::now(),
        }
    }

    /// Writes the checkpoint `text` makes, if the interval has passed since the last.
    pub fn due(
        &mut self,
        text: impl FnOnce() -> Result<String, sylva::Error>,
    ) -> anyhow::Result<()> {
        if self.last.elapsed() >= self.every {
            self.save(text)?;
        }
        Ok(())
    }

    /// Writes the checkpoint `text` makes.
    pub fn save(
        &mut self,
        text: impl FnOnce() -> Result<String, sylva::Error>,
    ) -> anyhow::Result<()> {
        sylva::files::write(self.path, text()?.as_bytes())?;
        self.last = std::time::Instant::now();
        Ok(())
    }
}

/// Reads `--height`: metres from 0.01 to 1000.
pub fn parse_height(text: &str) -> Result<f32, String> {
    let (lo, hi) = sylva::assets::HEIGHTS;
    match text.trim().parse::<f32>() {
        Ok(m) if (lo..=hi).contains(&m) => Ok(m),
        _ => Err(format!("expected metres from {lo} to {hi}; got {text:?}")),
    }
}

/// Work estimated to take this long or longer is announced before it starts, seconds.
const ANNOUNCE_SECONDS: f64 = 60.0;

/// Says on stderr, before it starts, how long work may take when that is a minute or more
/// (and within the time budget: beyond it the work is refused, with the estimate).
pub fn announce(seconds: f64, what: impl Display, advice: &str) {
    if seconds >= ANNOUNCE_SECONDS && seconds <= sylva::core::budget::max_time().as_secs_f64() {
        eprintln!(
            "note: {what} may take up to about {} (estimated at the plants' bounds); {advice} \
             to make it shorter",
            Seconds(seconds)
        );
    }
}

/// A spinner shown while a genome grows, taken off the screen when dropped.
pub struct Growing(Option<ProgressBar>);

impl Drop for Growing {
    fn drop(&mut self) {
        if let Some(spinner) = &self.0 {
            spinner.finish_and_clear();
        }
    }
}

/// Before a genome grows alone (`grow`, `render`): announces growth that may take a minute
/// or more, with a spinner showing the time spent until the result is dropped.
pub fn growing(genome: &sylva::Genome) -> Growing {
    Growing(growing_spinner(genome))
}

fn growing_spinner(genome: &sylva::Genome) -> Option<ProgressBar> {
    let seconds = genome.growth_seconds()?;
    announce(
        seconds,
        "growing the plant",
        "lower `max_symbols` and `max_modules` in its `physiology`",
    );
    if seconds < ANNOUNCE_SECONDS {
        return None;
    }
    let spinner = ProgressBar::new_spinner()
        .with_style(
            ProgressStyle::with_template("{spinner} growing ({elapsed}, up to about {msg})")
                .expect("the template is valid"),
        )
        .with_message(Seconds(seconds).to_string());
    spinner.enable_steady_tick(std::time::Duration::from_millis(250));
    Some(spinner)
}

/// A progress bar over `len` units on stderr, named by `prefix` (drawn only on a
/// terminal).
pub fn progress_bar(len: u64, prefix: &'static str) -> ProgressBar {
    ProgressBar::new(len)
        .with_style(
            ProgressStyle::with_template(
                "{spinner} {prefix} {pos}/{len} {bar:30} ({elapsed}, eta {eta})",
            )
            .expect("the template is valid"),
        )
        .with_prefix(prefix)
}

/// A result whose limit refusals name the input file they follow from.
pub trait InFile<T> {
    /// Limit and budget refusals become bad input in `path` ([`sylva::Error::in_file`]).
    fn in_file(self, path: &Path) -> Result<T, sylva::Error>;
}

impl<T> InFile<T> for Result<T, sylva::Error> {
    fn in_file(self, path: &Path) -> Result<T, sylva::Error> {
        self.map_err(|e| e.in_file(path))
    }
}

/// The genome a command grows from `path` and the options its file gives: a species
/// preset's (`.toml`, [`sylva::preset::Preset`]), or a genome file's defaults.
pub fn load_input(
    models: &sylva::Registry,
    path: &Path,
) -> Result<(sylva::Genome, sylva::GrowOptions), sylva::InputError> {
    if sylva::preset::Preset::is_preset(path) {
        let preset = sylva::preset::Preset::load(models, path)?;
        Ok((preset.genome, preset.options))
    } else {
        Ok((models.load_genome(path)?, sylva::GrowOptions::default()))
    }
}

/// The growing flags a command takes, over the options its input file gave (a preset's).
pub struct GrowFlags<'a> {
    /// `--seed`.
    pub seed: Option<u64>,
    /// `--hide-roots`.
    pub hide_roots: bool,
    /// `--taper`.
    pub taper: Option<sylva::core::taper::PipeTaper>,
    /// `--height`.
    pub height: Option<f32>,
    /// `--foliage`, `--bark`, `--density`.
    pub dress: &'a DressArgs,
}

impl GrowFlags<'_> {
    /// `base` with every flag given in its place.
    pub fn over(&self, base: sylva::GrowOptions) -> sylva::GrowOptions {
        sylva::GrowOptions {
            seed: self.seed.or(base.seed),
            roots: base.roots && !self.hide_roots,
            taper: self.taper.or(base.taper),
            height: self.height.or(base.height),
            dress: self.dress.over(base.dress),
            ..base
        }
    }
}

/// The realism flags of `grow`, `render`, `evolve` and `match`: leaves or needles of a
/// kind at their real size, and a tiling bark.
#[derive(clap::Args, Debug, Default, Clone)]
pub struct DressArgs {
    /// Put leaves or needles of a kind on the plant, at their real size, drawn as
    /// alpha-cut cards (its own leaves become cards of the kind; a plant without leaves
    /// gets them on its last twigs): oak, birch, aspen, beech, maple, willow, ash, privet,
    /// pine, spruce, fir [default: the plant's own leaves].
    #[arg(long, value_name = "KIND", value_parser = parse_foliage)]
    pub foliage: Option<sylva::LeafKind>,
    /// Give the stems a tiling bark with its normal map: smooth, birch, furrowed, plated
    /// [default: the foliage kind's own bark, or the model's look].
    #[arg(long, value_name = "KIND", value_parser = parse_bark)]
    pub bark: Option<sylva::BarkKind>,
    /// Leaf cards per metre of twig, as a multiple of the kind's own, 0.25 to 4
    /// [default: 1].
    #[arg(long, value_name = "X", value_parser = parse_density, requires = "foliage")]
    pub density: Option<f32>,
}

impl DressArgs {
    /// Sets a config's `[output]` dress to what the flags give.
    pub fn apply(&self, output: &mut sylva::evolution::OutputConfig) {
        let dress = self.over(output.dress());
        (output.foliage, output.bark, output.density) = (dress.foliage, dress.bark, dress.density);
    }

    /// The dress these flags ask for, over `base` (a config's `[output]`, say).
    pub fn over(&self, base: sylva::Dress) -> sylva::Dress {
        sylva::Dress {
            foliage: self.foliage.or(base.foliage),
            bark: self.bark.or(base.bark),
            density: self.density.unwrap_or(base.density),
            ..base
        }
    }
}

fn parse_foliage(text: &str) -> Result<sylva::LeafKind, String> {
    text.parse()
        .map_err(|e: sylva::core::species::UnknownKind| e.to_string())
}

fn parse_bark(text: &str) -> Result<sylva::BarkKind, String> {
    text.parse()
        .map_err(|e: sylva::core::species::UnknownKind| e.to_string())
}

fn parse_density(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(x) if (0.25..=4.0).contains(&x) => Ok(x),
        _ => Err(format!("expected a multiple from 0.25 to 4; got {text:?}")),
    }
}

/// The wind flags of `grow` and `garden`.
#[derive(clap::Args, Debug, Default)]
pub struct WindArgs {
    /// Add a wind skin and a looping animation clip named `wind` (GLB only): joints along
    /// the trunk and branches, a sway that falls with branch radius, a phase per branch, and
    /// a `_WIND` flutter weight on leaves for engines that add shader flutter.
    #[arg(long)]
    wind: bool,
    /// Wind strength, 0 to 10 (1, the default, is a breeze).
    #[arg(long, value_name = "S", requires = "wind")]
    wind_strength: Option<f32>,
    /// Seconds one sway takes (the clip's length), 0.5 to 60; default 4.
    #[arg(long, value_name = "SECONDS", requires = "wind")]
    wind_period: Option<f32>,
}

impl WindArgs {
    /// The wind asked for, if any, checked against the output (a GLB).
    pub fn options(
        &self,
        output: &Path,
    ) -> Result<Option<sylva::mesh::wind::WindOptions>, sylva::InputError> {
        if !self.wind {
            return Ok(None);
        }
        let is_glb = output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
        if !is_glb
            && !output
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            return Err(sylva::InputError::new(
                "--wind",
                format!(
                    "wind needs a .glb output (skins and animation clips are glTF's), or a .png of `sylva render --wind-frames`; got {}",
                    output.display()
                ),
            ));
        }
        let defaults = sylva::mesh::wind::WindOptions::default();
        let strength = self.wind_strength.unwrap_or(defaults.strength);
        let period = self.wind_period.unwrap_or(defaults.period);
        sylva::mesh::wind::WindOptions::new(strength, period)
            .map(Some)
            .map_err(|e| {
                let flag = match e {
                    sylva::mesh::wind::WindError::Strength(_) => "--wind-strength",
                    sylva::mesh::wind::WindError::Period(_) => "--wind-period",
                };
                sylva::InputError::new(flag, e)
            })
    }
}

/// The `--quantize` flag of `grow` and `garden`.
#[derive(clap::Args, Debug, Default)]
pub struct QuantizeArgs {
    /// Store positions as 16-bit and normals as 8-bit integers (glTF's KHR_mesh_quantization,
    /// which a viewer must support to open the file): a smaller GLB, each position within
    /// 1/65534 of its plant's size. GLB only; not with --wind.
    #[arg(long)]
    quantize: bool,
}

impl QuantizeArgs {
    /// Whether to quantise, checked against the output (a GLB) and wind (refused with it).
    pub fn check(&self, output: &Path, wind: bool) -> Result<bool, sylva::InputError> {
        if !self.quantize {
            return Ok(false);
        }
        if !output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
        {
            return Err(sylva::InputError::new(
                "--quantize",
                format!(
                    "quantised positions are glTF's (KHR_mesh_quantization): give a .glb output; got {}",
                    output.display()
                ),
            ));
        }
        if wind {
            return Err(sylva::InputError::new(
                "--quantize",
                "wind GLBs are not quantised (a skinned mesh would need the dequantisation in its inverse bind matrices); drop --quantize or --wind",
            ));
        }
        Ok(true)
    }
}

/// Size of pictures of whole scenes (gardens, experiments): wide, for a plot of plants.
pub const SCENE_PICTURE: (u32, u32) = (1200, 800);

/// The worker pool for `--threads` (0: one per core).
pub fn pool(threads: u32) -> Result<sylva::core::par::Pool, sylva::Error> {
    Ok(sylva::core::par::Pool::with_threads(threads as usize)?)
}

/// Parses `WIDTHxDEPTH` in metres, each from 0.1 to 100,000.
pub fn parse_area(text: &str) -> Result<(f64, f64), String> {
    let bad = || {
        format!("expected WIDTHxDEPTH in metres, each from 0.1 to 100000, like 30x20; got {text:?}")
    };
    let (w, d) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: f64 = w.trim().parse().map_err(|_| bad())?;
    let d: f64 = d.trim().parse().map_err(|_| bad())?;
    if [w, d]
        .iter()
        .all(|v| v.is_finite() && (0.1..=100_000.0).contains(v))
    {
        Ok((w, d))
    } else {
        Err(bad())
    }
}

/// Parses `WIDTHxHEIGHT`, each 16 to 8192 pixels.
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let bad =
        || format!("expected WIDTHxHEIGHT with each from 16 to 8192, like 800x600; got {text:?}");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if (16..=8192).contains(&w) && (16..=8192).contains(&h) {
        Ok((w, h))
    } else {
        Err(bad())
    }
}

/// Parses the pipe-model exponent of `--taper`, 2 to 3.
pub fn parse_taper(text: &str) -> Result<sylva::core::taper::PipeTaper, String> {
    let bad = || format!("expected the pipe-model exponent, a number from 2 to 3; got {text:?}");
    let e: f64 = text.trim().parse().map_err(|_| bad())?;
    sylva::core::taper::PipeTaper::new(e).map_err(|_| bad())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_areas() {
        assert_eq!(parse_size("800x600"), Ok((800, 600)));
        assert_eq!(parse_size("64X64"), Ok((64, 64)));
        for bad in ["", "800", "x600", "0x10", "800x99999", "-5x10", "axb"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_area("30x20"), Ok((30.0, 20.0)));
        for bad in ["", "0x10", "1e9x1", "nanx1", "5"] {
            assert!(parse_area(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_taper("2.5").map(|t| t.exponent), Ok(2.5));
        for bad in ["", "1.9", "3.01", "nan", "inf", "two"] {
            assert!(parse_taper(bad).is_err(), "{bad}");
        }
    }
}
