//! Reports people read: the statistics table (CSV), the generations of an auto match's
//! trials (CSV) and the fitness plot (SVG). An experiment's report is its model's own.

use std::fmt::Write as _;

use plotters::prelude::*;
use sylva_evolve::GenerationStats;
use sylva_evolve::map::MapStats;

/// `stats.csv`: `generation,best,mean,<term...>,evals_per_s`, one row per generation.
/// Numbers are written in Rust's shortest round-trip form, so equal runs give equal bytes
/// (except `evals_per_s`, which is wall-clock).
pub fn stats_csv(term_names: &[String], stats: &[GenerationStats]) -> String {
    let mut out = String::from("generation,best,mean");
    for name in term_names {
        out.push(',');
        out.push_str(name);
    }
    out.push_str(",evals_per_s\n");
    for s in stats {
        let _ = write!(out, "{},{},{}", s.generation, s.best, s.mean);
        // One cell per term named in the header, empty where the best had none (a genome
        // that could not grow), so every row is as wide as the header.
        for i in 0..term_names.len() {
            match s.best_terms.get(i) {
                Some(t) => {
                    let _ = write!(out, ",{t}");
                }
                None => out.push(','),
            }
        }
        let _ = writeln!(out, ",{:.0}", s.evals_per_second());
    }
    out
}

/// `trials.csv` of an auto match: `model,phase,generation,best,mean,iou`, one row per
/// generation each model bred in its trials (`phase` is `trial` or `runoff`), in the order
/// they were bred; a model left out has no rows. No wall-clock figure: equal matches give
/// equal bytes.
pub fn trials_csv(log: &crate::evolution::outline::TrialLog) -> String {
    let mut out = String::from("model,phase,generation,best,mean,iou\n");
    for trial in log.trials() {
        let phase = if trial.runoff { "runoff" } else { "trial" };
        for r in &trial.rows {
            let _ = writeln!(
                out,
                "{},{phase},{},{},{},{}",
                trial.model, r.generation, r.best, r.mean, r.iou
            );
        }
    }
    out
}

/// `stats.csv` of a map run: per generation, the cells filled, coverage, QD-score, best
/// and mean fitness of the elites, offspring that improved the map, and evaluations.
pub fn map_stats_csv(stats: &[MapStats]) -> String {
    let mut out =
        String::from("generation,filled,coverage,qd_score,best,mean,improved,evaluations\n");
    for s in stats {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{}",
            s.generation,
            s.filled,
            s.coverage,
            s.qd_score,
            s.best,
            s.mean,
            s.improved,
            s.evaluations
        );
    }
    out
}

pub use crate::error::PlotError;

/// `fitness.svg`: best and mean fitness per generation.
pub fn fitness_svg(stats: &[GenerationStats], title: &str) -> Result<String, PlotError> {
    let err = |e: &dyn std::fmt::Display| PlotError(e.to_string());
    let finite = |v: f64| v.is_finite().then_some(v);
    let values: Vec<f64> = stats
        .iter()
        .flat_map(|s| [finite(s.best), finite(s.mean)])
        .flatten()
        .collect();
    let (mut lo, mut hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        (lo, hi) = (0.0, 1.0);
    }
    if hi - lo < 1e-9 {
        hi = lo + 1.0;
    }
    let pad = 0.05 * (hi - lo);
    let last = stats.last().map_or(1, |s| s.generation.max(1));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (800, 480)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d(0u32..last, (lo - pad)..(hi + pad))
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("generation")
            .y_desc("fitness")
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| err(&e))?;
        let series = [
            ("best", RGBColor(34, 120, 50), true),
            ("mean", RGBColor(200, 110, 30), false),
        ];
        for (name, color, is_best) in series {
            let points = stats.iter().filter_map(move |s| {
                let v = if is_best { s.best } else { s.mean };
                v.is_finite().then_some((s.generation, v))
            });
            chart
                .draw_series(LineSeries::new(points, color.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(name)
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK.mix(0.3))
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))?;
    }
    Ok(svg)
}
