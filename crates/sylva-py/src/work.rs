//! Long native calls, run so that Ctrl-C is heard while they work and a Python fitness
//! function is called from the thread that made the call.
//!
//! Python hears a signal only on its main thread, between bytecodes: a call that stays in
//! Rust for minutes hears nothing. [`work`] runs the call on a thread of its own and keeps
//! the calling thread free: it checks for signals every [`TICK`], sets the run's [`Stop`] when
//! one raises (the library then ends the work within one member's evaluation), and calls the
//! run's fitness function for the batches of plants the work sends it. So the user's function
//! runs on the thread that called `step`, as Python code expects (a KeyboardInterrupt raised
//! inside it stops the run too), and the GIL is held only while Python runs.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, Sender, SyncSender};
use std::sync::{Arc, Mutex};
use std::thread::ThreadId;
use std::time::Duration;

use numpy::{PyArrayDescrMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::PyList;
use sylva::evolution::{ScorerError, Stop};
use sylva::{Grown, PlantScorer};

use crate::errors::bad_value;
use crate::plant::Plant;

/// How often the calling thread looks for signals while native work runs: Ctrl-C stops it
/// within this and one member's evaluation.
const TICK: Duration = Duration::from_millis(25);

/// What the working thread asks of the calling one.
enum Message {
    /// The work ended (its result is the thread's).
    Done,
    /// Score these plants with the Python function and send the scores back.
    Score(Vec<Grown>, SyncSender<PyResult<Vec<f64>>>),
}

/// A Python fitness function: called with a list of `sylva.Plant`, it returns one number
/// per plant (a sequence or a numpy array).
pub struct PyFitness {
    function: Py<PyAny>,
    /// Where to send batches while [`work`] serves them; none: the function is called from
    /// the asking thread.
    server: Mutex<Option<Sender<Message>>>,
    /// Calls, plants, and nanoseconds spent calling the function (its own work included)
    /// and dropping the plants after, for `benches/fitness_overhead.py`.
    spent: [AtomicU64; 4],
}

impl PyFitness {
    pub fn new(function: Py<PyAny>) -> PyFitness {
        PyFitness {
            function,
            server: Mutex::new(None),
            spent: Default::default(),
        }
    }

    /// Calls made, plants scored, seconds spent in those calls (making the plants' Python
    /// objects, the function's own work, reading its answer), and seconds spent dropping the
    /// plants afterwards (their meshes' memory given back).
    pub fn spent(&self) -> (u64, u64, f64, f64) {
        let [calls, plants, calling, dropping] = &self.spent;
        let read = |n: &AtomicU64| n.load(Ordering::Relaxed);
        let seconds = |n: &AtomicU64| read(n) as f64 * 1e-9;
        (
            read(calls),
            read(plants),
            seconds(calling),
            seconds(dropping),
        )
    }

    /// The Python function.
    pub fn function(&self) -> &Py<PyAny> {
        &self.function
    }

    fn serve(&self, server: Option<Sender<Message>>) {
        *self.server.lock().unwrap_or_else(|e| e.into_inner()) = server;
    }

    /// The function called with `plants`, its answer read as one number per plant.
    fn call(&self, py: Python<'_>, plants: Vec<Grown>) -> PyResult<Vec<f64>> {
        let started = std::time::Instant::now();
        let count = plants.len();
        let plants = plants
            .into_iter()
            .map(|g| Py::new(py, Plant::new(g)))
            .collect::<PyResult<Vec<_>>>()?;
        let list = PyList::new(py, plants)?;
        let scores = self
            .function
            .bind(py)
            .call1((&list,))
            .and_then(|answer| scores(py, &answer, count));
        let called = started.elapsed();
        drop(list);
        let [calls, plants, calling, dropping] = &self.spent;
        let nanos = |d: std::time::Duration| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX);
        calls.fetch_add(1, Ordering::Relaxed);
        plants.fetch_add(count as u64, Ordering::Relaxed);
        calling.fetch_add(nanos(called), Ordering::Relaxed);
        dropping.fetch_add(nanos(started.elapsed() - called), Ordering::Relaxed);
        scores
    }
}

impl PlantScorer for PyFitness {
    fn score(&self, plants: Vec<Grown>) -> Result<Vec<f64>, ScorerError> {
        let server = self
            .server
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone();
        let scores = match server {
            Some(server) => {
                let (reply, answer) = mpsc::sync_channel(1);
                let asked = server.send(Message::Score(plants, reply));
                match (asked, answer.recv()) {
                    (Ok(()), Ok(scores)) => scores,
                    _ => Err(PyRuntimeError::new_err(
                        "the thread that calls the fitness function stopped answering",
                    )),
                }
            }
            None => Python::attach(|py| self.call(py, plants)),
        };
        scores.map_err(|e| Box::new(e) as ScorerError)
    }
}

/// What a fitness function returned, as `count` numbers: a sequence or a 1-D numpy array of
/// numbers; anything else raises `TypeError` or `InputError` naming `fitness`.
fn scores(py: Python<'_>, answer: &Bound<'_, PyAny>, count: usize) -> PyResult<Vec<f64>> {
    let expected = format!("one number per plant (a sequence or numpy array of {count} floats)");
    let refused = |got: String| {
        PyTypeError::new_err(format!(
            "`fitness`: the fitness function must return {expected}; it returned {got}"
        ))
    };
    let type_name = || {
        answer
            .get_type()
            .name()
            .map_or_else(|_| "?".into(), |n| n.to_string())
    };
    if answer.is_instance_of::<pyo3::types::PyString>() || answer.is_none() {
        return Err(refused(format!("a {}", type_name())));
    }
    if let Ok(array) = answer.cast::<PyUntypedArray>()
        && !matches!(array.dtype().kind(), b'i' | b'u' | b'f' | b'b')
    {
        return Err(refused(format!("an array of dtype {}", array.dtype())));
    }
    let numpy = py.import("numpy")?;
    let array = numpy
        .call_method1("asarray", (answer, numpy::dtype::<f64>(py)))
        .map_err(|e| refused(format!("a {} ({})", type_name(), e.value(py))))?;
    let array = array
        .cast_into::<numpy::PyArrayDyn<f64>>()
        .map_err(|e| refused(e.to_string()))?;
    let shape = array.shape().to_vec();
    if shape != [count] {
        let got = match shape.as_slice() {
            [] => "a single number".to_owned(),
            [1] => "1 number".to_owned(),
            [n] => format!("{n} numbers"),
            s => format!(
                "an array of shape ({})",
                s.iter()
                    .map(ToString::to_string)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        return Err(bad_value(
            "fitness",
            format!(
                "the fitness function returned {got} for a batch of {count} plants; expected {expected}"
            ),
        ));
    }
    let values = numpy::PyArrayMethods::readonly(&array);
    Ok(values.as_array().iter().copied().collect())
}

/// The thread that is serving a run's fitness function while it works, if any: the run
/// cannot be read from that function (its work holds it).
#[derive(Default)]
pub struct Serving(Mutex<Option<ThreadId>>);

impl Serving {
    /// Whether the current thread serves the run's work.
    pub fn here(&self) -> bool {
        *self.0.lock().unwrap_or_else(|e| e.into_inner()) == Some(std::thread::current().id())
    }

    fn set(&self, thread: Option<ThreadId>) {
        *self.0.lock().unwrap_or_else(|e| e.into_inner()) = thread;
    }
}

/// Runs `job` (native work of a run with `stop` and the fitness function `fitness`) on a
/// thread of its own, while this thread checks for signals and calls `fitness` for the
/// batches `job` sends. A signal whose handler raises (Ctrl-C's `KeyboardInterrupt`) sets
/// `stop`, and its exception is raised once `job` has ended (within one member's evaluation).
pub fn work<T: Send>(
    py: Python<'_>,
    stop: &Stop,
    fitness: Option<&Arc<PyFitness>>,
    serving: &Serving,
    job: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    py.check_signals()?;
    stop.reset();
    let (sender, messages) = mpsc::channel();
    if let Some(f) = fitness {
        f.serve(Some(sender.clone()));
    }
    serving.set(Some(std::thread::current().id()));
    let (result, raised) = std::thread::scope(|scope| {
        let done = sender.clone();
        let worker = scope.spawn(move || {
            let result = job();
            let _ = done.send(Message::Done);
            result
        });
        let mut raised: Option<PyErr> = None;
        let mut messages = messages;
        loop {
            // The receiver goes into the call and back: it may not be shared across threads.
            let (back, message) = py.detach(move || {
                let message = messages.recv_timeout(TICK);
                (messages, message)
            });
            messages = back;
            match message {
                Ok(Message::Done) | Err(RecvTimeoutError::Disconnected) => break,
                Ok(Message::Score(plants, reply)) => {
                    let scores = match (&raised, fitness) {
                        (None, Some(f)) => f.call(py, plants),
                        _ => Err(PyKeyboardInterrupt::new_err("stopped")),
                    };
                    if let Err(e) = &scores
                        && raised.is_none()
                        && e.is_instance_of::<PyKeyboardInterrupt>(py)
                    {
                        // Ctrl-C while the function ran: the run stops too.
                        stop.stop();
                        raised = Some(e.clone_ref(py));
                    }
                    let _ = reply.send(scores);
                }
                // A worker that panicked sends nothing: its panic is raised below.
                Err(RecvTimeoutError::Timeout) if worker.is_finished() => break,
                Err(RecvTimeoutError::Timeout) => {
                    if raised.is_none()
                        && let Err(e) = py.check_signals()
                    {
                        stop.stop();
                        raised = Some(e);
                    }
                }
            }
        }
        let result = py.detach(|| worker.join());
        (result, raised)
    });
    serving.set(None);
    if let Some(f) = fitness {
        f.serve(None);
    }
    let result = result.unwrap_or_else(|panic| std::panic::resume_unwind(panic));
    match raised {
        Some(e) => Err(e),
        None => Ok(result),
    }
}
