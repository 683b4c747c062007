//! What a session tells the pages watching it, as server-sent events: a design run's
//! generations and changes of status, a garden's progress while it grows. Each event is a
//! name and one JSON object.

use std::collections::HashMap;
use std::sync::Mutex;

use tokio::sync::broadcast;

use crate::Studio;

/// An event: its name and its data.
#[derive(Clone, Debug)]
pub struct SessionEvent {
    /// `generation`, `status` or `progress`.
    pub name: &'static str,
    /// One JSON object.
    pub data: serde_json::Value,
}

/// The channels of the sessions pages are watching (or that have said something).
#[derive(Default)]
pub struct Events {
    channels: Mutex<HashMap<i64, broadcast::Sender<SessionEvent>>>,
}

impl Events {
    /// The channel of a session's events.
    pub fn channel(&self, session: i64) -> broadcast::Sender<SessionEvent> {
        self.channels
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .entry(session)
            .or_insert_with(|| broadcast::channel(256).0)
            .clone()
    }

    /// Tells the pages watching `session`; nobody watching is fine.
    pub fn send(&self, session: i64, name: &'static str, data: serde_json::Value) {
        let _ = self.channel(session).send(SessionEvent { name, data });
    }
}

/// Reports growth of `steps` steps in `session`'s channel as `progress` events
/// (`{"what", "step", "steps"}`), about every 2% and at the end.
pub fn progress(
    studio: &Studio,
    session: i64,
    what: &'static str,
    steps: u32,
) -> impl FnMut(u32) + use<> {
    let studio = studio.clone();
    let every = (steps / 50).max(1);
    move |step| {
        if step % every == 0 || step == steps {
            let data = serde_json::json!({ "what": what, "step": step, "steps": steps });
            studio.events.send(session, "progress", data);
        }
    }
}
