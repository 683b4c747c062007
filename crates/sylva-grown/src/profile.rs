//! A crown's profile: its rows of stretches from the crown's base to the top, as shares of
//! the tree's height, drawn from a picture's front and side outlines ([`Profile::from_target`])
//! or read from a genome file, and checked as read. The envelope ([`crate::crown`]) grows
//! from it; a genome carries it, as its `envelope`.

use serde::{Deserialize, Serialize};
use sylva_model::TargetProfile;

/// One view's stretches at one height, `[left, right]` each (or `[back, front]`).
pub type Stretches = Vec<[f32; 2]>;

/// A row of an envelope or a profile: the stretches of x seen from the front and of z seen
/// from the side.
pub type Row = [Stretches; 2];

/// The rectangle around a view's stretches, `[least, greatest]`: empty (least ≥ greatest)
/// for none.
pub(crate) fn hull(stretches: &[[f32; 2]]) -> [f32; 2] {
    (stretches.iter())
        .filter(|s| s[0] < s[1])
        .fold([f32::MAX, f32::MIN], |h, s| {
            [h[0].min(s[0]), h[1].max(s[1])]
        })
}

/// Why an envelope cannot be grown into.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EnvelopeError {
    /// Its rows hold no volume.
    #[error(
        "the crown's envelope is empty or flat (no volume between {base:.2} and {top:.2} m); \
         expected a crown with width and depth"
    )]
    Empty {
        /// The lowest row's height.
        base: f32,
        /// The highest row's height.
        top: f32,
    },
    /// Too few attraction points fell inside it.
    #[error(
        "only {placed} of {asked} attraction points fit in the crown's envelope; expected an \
         envelope of some volume"
    )]
    TooThin {
        /// Points placed.
        placed: usize,
        /// Points asked for.
        asked: usize,
    },
}

/// A crown's envelope drawn from pictures rather than a shape: where the crown begins and
/// its rows to the top, all as shares of the tree's height, so the tree's `height` scales
/// it. A genome that carries one grows into it; its crown shape, `crown_base`, `width` and
/// `depth` then say nothing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, try_from = "RawProfile")]
pub struct Profile {
    /// Where the crown begins, as a share of the height, 0 to 1.
    pub base: f32,
    /// Rows from the crown's base to the top, each the stretches of x (front view) and of
    /// z (side view) as shares of the height from the trunk's foot: 1 to
    /// [`MAX_PROFILE_ROWS`] rows, at most [`MAX_STRETCHES`] stretches a view, each number
    /// within ±[`MAX_PROFILE_REACH`]. A file may give a view one stretch as `[left, right]`
    /// rather than `[[left, right]]` (as genomes written before stretches did).
    pub rows: Vec<Row>,
}

/// Most stretches a profile's view holds at one height.
pub const MAX_STRETCHES: usize = 32;

/// Most rows a profile holds.
pub const MAX_PROFILE_ROWS: usize = 256;

/// How far a profile's crown reaches from its foot, as a share of the height.
pub const MAX_PROFILE_REACH: f32 = 3.0;

/// Rows a profile is drawn from a target with.
const PROFILE_ROWS: usize = 48;

/// A profile as read, before its checks.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawProfile {
    base: f32,
    rows: Vec<[RawView; 2]>,
}

/// A view of a profile's row as read: one stretch, or a list of them.
#[derive(Deserialize)]
#[serde(
    untagged,
    expecting = "a view's stretches, [[left, right], ...], or one stretch, [left, right]"
)]
enum RawView {
    One([f32; 2]),
    Many(Stretches),
}

impl From<RawView> for Stretches {
    fn from(view: RawView) -> Stretches {
        match view {
            RawView::One(stretch) => vec![stretch],
            RawView::Many(stretches) => stretches,
        }
    }
}

impl TryFrom<RawProfile> for Profile {
    type Error = String;
    fn try_from(raw: RawProfile) -> Result<Profile, String> {
        if !(0.0..1.0).contains(&raw.base) {
            return Err(format!(
                "`envelope.base` must be a share of the height from 0 to 1, got {}",
                raw.base
            ));
        }
        if raw.rows.is_empty() || raw.rows.len() > MAX_PROFILE_ROWS {
            return Err(format!(
                "`envelope.rows` must hold 1 to {MAX_PROFILE_ROWS} rows, got {}",
                raw.rows.len()
            ));
        }
        let rows: Vec<Row> = (raw.rows.into_iter())
            .map(|[x, z]| [x.into(), z.into()])
            .collect();
        let reach = -MAX_PROFILE_REACH..=MAX_PROFILE_REACH;
        for (i, row) in rows.iter().enumerate() {
            let stretches = row.iter().flatten();
            if row.iter().any(|view| view.len() > MAX_STRETCHES) {
                return Err(format!(
                    "`envelope.rows[{i}]` must hold at most {MAX_STRETCHES} stretches a view"
                ));
            }
            if let Some(s) = stretches
                .into_iter()
                .find(|s| !(reach.contains(&s[0]) && reach.contains(&s[1]) && s[0] <= s[1]))
            {
                return Err(format!(
                    "`envelope.rows[{i}]` must hold stretches [left, right], left ≤ right, \
                     of shares of the height from -{MAX_PROFILE_REACH} to \
                     {MAX_PROFILE_REACH}, got {s:?}"
                ));
            }
        }
        Ok(Profile {
            base: raw.base,
            rows,
        })
    }
}

impl Profile {
    /// The crown a match's target shows ([`TargetProfile`]): the rows above the trunk (the
    /// first row from the foot at least [`CROWN_WIDTH`] as wide as the widest, in either
    /// view) to the top, each view's stretches of ink, drawn in [`PROFILE_ROWS`] rows
    /// (gaps narrower than [`GAP`] closed: a crown's leaves fill them). `Err` for a target
    /// with no crown to grow into.
    pub fn from_target(target: &TargetProfile) -> Result<Profile, EnvelopeError> {
        let n = target.front.len().min(target.side.len());
        let width = |r: &[[f32; 2]]| {
            let [lo, hi] = hull(r);
            (hi - lo).max(0.0)
        };
        let widest = |rows: &[Stretches]| rows.iter().map(|r| width(r)).fold(0.0, f32::max);
        let (front, side) = (&target.front[..n], &target.side[..n]);
        let (wf, ws) = (widest(front), widest(side));
        let crowned =
            |i: usize| width(&front[i]) >= CROWN_WIDTH * wf || width(&side[i]) >= CROWN_WIDTH * ws;
        let top = (0..n)
            .rev()
            .find(|&i| width(&front[i]) > 0.0 && width(&side[i]) > 0.0);
        let (Some(base), Some(top)) = ((0..n).find(|&i| crowned(i)), top) else {
            return Err(EnvelopeError::Empty {
                base: 0.0,
                top: 1.0,
            });
        };
        if wf <= 0.0 || ws <= 0.0 || top <= base {
            return Err(EnvelopeError::Empty {
                base: base as f32 / n as f32,
                top: (top + 1) as f32 / n as f32,
            });
        }
        let span = top + 1 - base;
        let count = PROFILE_ROWS.min(span);
        let rows = (0..count)
            .map(|k| {
                let (a, b) = (base + k * span / count, base + (k + 1) * span / count);
                let union = |rows: &[Stretches]| join(rows[a..b.max(a + 1)].iter().flatten());
                [union(front), union(side)]
            })
            .collect();
        Ok(Profile {
            base: base as f32 / n as f32,
            rows,
        })
    }
}

/// Stretches of ink closer than this share of the height are one stretch in a profile.
pub const GAP: f32 = 0.02;

/// The union of `stretches` left to right, those closer than [`GAP`] joined, each clamped
/// to ±[`MAX_PROFILE_REACH`], at most [`MAX_STRETCHES`] (the narrowest gaps closed first).
fn join<'a>(stretches: impl Iterator<Item = &'a [f32; 2]>) -> Stretches {
    let reach = |v: f32| v.clamp(-MAX_PROFILE_REACH, MAX_PROFILE_REACH);
    let mut sorted: Stretches = (stretches.filter(|s| s[0] < s[1]))
        .map(|s| s.map(reach))
        .collect();
    sorted.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut joined: Stretches = Vec::with_capacity(sorted.len());
    for s in sorted {
        match joined.last_mut() {
            Some(last) if s[0] - last[1] < GAP => last[1] = last[1].max(s[1]),
            _ => joined.push(s),
        }
    }
    while joined.len() > MAX_STRETCHES {
        let narrowest = (1..joined.len())
            .min_by(|&i, &j| {
                let gap = |k: usize| joined[k][0] - joined[k - 1][1];
                gap(i).total_cmp(&gap(j))
            })
            .expect("more than one stretch");
        let right = joined.remove(narrowest);
        joined[narrowest - 1][1] = right[1];
    }
    joined
}

/// A row is the crown's when it is at least this share as wide as the crown's widest row:
/// narrower rows below the crown are the trunk.
pub const CROWN_WIDTH: f32 = 0.25;
