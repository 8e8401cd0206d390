//! What a `reproduce` run has finished, so that `reproduce --resume` can skip it.
//!
//! The ledger is `reproduce-state.json` in the output directory: the run's scale and seed, and
//! one entry per finished step (a beam map, a render, a convergence study) holding the numbers
//! the report needs from it. It is rewritten atomically after each step, so an interrupted run
//! keeps every step it finished. A resumed run reuses a step only if its entry is there *and*
//! its image is still on disk; anything else is run again. References are reloaded from their
//! EXR files, which hold `f32`: so that a resumed report is the same as an uninterrupted one,
//! `reproduce` always compares against the reference as written (rounded to `f32`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::error::WriteError;

/// File name of the ledger in the output directory.
pub const LEDGER_FILE: &str = "reproduce-state.json";
/// Version of the ledger's format; a ledger of another version is not reused.
const VERSION: u32 = 1;

#[derive(Debug, Serialize, Deserialize)]
struct State {
    version: u32,
    scale: String,
    seed: u64,
    done: BTreeMap<String, serde_json::Value>,
}

/// Why an earlier run's ledger cannot be resumed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LedgerError {
    /// The ledger exists but cannot be read or parsed.
    #[error("--resume: cannot read `{path}` ({message}); remove it to start afresh")]
    Unreadable {
        /// The ledger.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The earlier run used another scale or seed.
    #[error(
        "--resume: `{path}` is a run at scale `{scale}` with seed {seed}; resume it with \
         `--scale {scale} --seed {seed}`, or run without --resume to start afresh"
    )]
    Mismatch {
        /// The ledger.
        path: PathBuf,
        /// Its scale.
        scale: String,
        /// Its seed.
        seed: u64,
    },
}

/// The ledger of one `reproduce` run (see the module docs).
#[derive(Debug)]
pub struct Ledger {
    path: PathBuf,
    state: State,
    /// Entries of the earlier run (empty unless resuming).
    earlier: BTreeMap<String, serde_json::Value>,
    reused: usize,
    steps: usize,
}

impl Ledger {
    /// Opens the ledger of a run into `out` at `scale` and `seed`. With `resume`, the steps an
    /// earlier run with the same scale and seed recorded are offered by [`Ledger::reuse`];
    /// without it, the earlier ledger is replaced at the first step.
    pub fn open(out: &Path, scale: &str, seed: u64, resume: bool) -> Result<Self, LedgerError> {
        let path = out.join(LEDGER_FILE);
        let mut earlier = BTreeMap::new();
        if resume && path.exists() {
            let unreadable = |message: String| LedgerError::Unreadable {
                path: path.clone(),
                message,
            };
            let bytes = std::fs::read(&path).map_err(|e| unreadable(e.to_string()))?;
            let old: State =
                serde_json::from_slice(&bytes).map_err(|e| unreadable(e.to_string()))?;
            if old.version != VERSION {
                return Err(unreadable(format!(
                    "format version {}, this build writes {VERSION}",
                    old.version
                )));
            }
            if old.scale != scale || old.seed != seed {
                return Err(LedgerError::Mismatch {
                    path,
                    scale: old.scale,
                    seed: old.seed,
                });
            }
            earlier = old.done;
        }
        Ok(Ledger {
            path,
            state: State {
                version: VERSION,
                scale: scale.to_string(),
                seed,
                done: BTreeMap::new(),
            },
            earlier,
            reused: 0,
            steps: 0,
        })
    }

    /// The earlier run's result of step `key`, if it recorded one and every file in `files`
    /// still exists. A reused step is recorded again in this run's ledger.
    pub fn reuse<T: DeserializeOwned>(
        &mut self,
        key: &str,
        files: &[&Path],
    ) -> Result<Option<T>, WriteError> {
        self.steps += 1;
        let Some(value) = self.earlier.get(key) else {
            return Ok(None);
        };
        if !files.iter().all(|f| f.is_file()) {
            return Ok(None);
        }
        let Ok(parsed) = serde_json::from_value::<T>(value.clone()) else {
            return Ok(None);
        };
        self.state.done.insert(key.to_string(), value.clone());
        self.reused += 1;
        self.save()?;
        Ok(Some(parsed))
    }

    /// Records that step `key` finished with `value`, and saves the ledger.
    pub fn record<T: Serialize>(&mut self, key: &str, value: &T) -> Result<(), WriteError> {
        let value = serde_json::to_value(value).map_err(|e| {
            WriteError::Output(tracer::error::OutputError::Encode {
                path: self.path.clone(),
                message: e.to_string(),
            })
        })?;
        self.state.done.insert(key.to_string(), value);
        self.save()
    }

    /// Step `key` of the run: the earlier run's result when it may be reused
    /// ([`Ledger::reuse`]), else `run()`'s, recorded. `progress` gets `label` before the work,
    /// or `label (done earlier)` when nothing is run.
    pub fn step<T, E>(
        &mut self,
        key: &str,
        files: &[&Path],
        progress: &mut dyn FnMut(&str),
        label: &str,
        run: impl FnOnce() -> Result<T, E>,
    ) -> Result<T, E>
    where
        T: Serialize + DeserializeOwned,
        E: From<WriteError>,
    {
        if let Some(done) = self.reuse(key, files)? {
            progress(&format!("{label} (done earlier)"));
            return Ok(done);
        }
        progress(label);
        let value = run()?;
        self.record(key, &value)?;
        Ok(value)
    }

    /// How many steps were reused, of how many asked about.
    pub fn reused(&self) -> (usize, usize) {
        (self.reused, self.steps)
    }

    fn save(&self) -> Result<(), WriteError> {
        let bytes = serde_json::to_vec_pretty(&self.state).map_err(|e| {
            WriteError::Output(tracer::error::OutputError::Encode {
                path: self.path.clone(),
                message: e.to_string(),
            })
        })?;
        tracer::output::write_atomic(&self.path, &bytes)?;
        Ok(())
    }
}
