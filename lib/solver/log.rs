//! What the user sees during a solve: one line per Newton iteration (increment,
//! iteration, residual, energy) — as a progress bar on a terminal, as plain log
//! lines otherwise — and the convergence history as a CSV to plot.

use std::io::{IsTerminal, Write};

use indicatif::{ProgressBar, ProgressStyle};

use crate::format::scres::{IncrementInfo, IterationLog};

/// How much to print.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verbosity {
    /// Nothing at all (an MPI rank other than the first: rank 0 speaks for all).
    Silent,
    /// Warnings and errors only.
    Quiet,
    Normal,
}

/// One Newton iteration as reported.
#[derive(Debug, Clone, Copy)]
pub struct IterationEvent {
    pub increment: usize,
    pub n_increments: usize,
    pub load_factor: f64,
    pub attempt: u32,
    pub iteration: u32,
    pub residual: f64,
    pub energy: f64,
    pub seconds_assembly: f64,
    pub seconds_factor: f64,
    pub seconds_solve: f64,
    pub seconds_contact: f64,
    /// Slave nodes pressed into their master (all pairs).
    pub contact_active: u32,
    /// Uzawa update the Newton solve follows.
    pub augmentation: u32,
    /// Krylov iterations of the linear solve.
    pub krylov_iterations: u32,
}

impl IterationEvent {
    /// A logged Newton iteration `row` of attempt `attempt` of increment `increment`
    /// (of `n_increments`) at load factor `load_factor`.
    pub fn from_row(increment: usize, n_increments: usize, load_factor: f64, attempt: u32, row: &IterationLog) -> Self {
        Self {
            increment,
            n_increments,
            load_factor,
            attempt,
            iteration: row.iteration,
            residual: row.residual,
            energy: row.energy,
            seconds_assembly: row.seconds_assembly,
            seconds_factor: row.seconds_factor,
            seconds_solve: row.seconds_solve,
            seconds_contact: row.seconds_contact,
            contact_active: row.contact_active,
            augmentation: row.augmentation,
            krylov_iterations: row.krylov_iterations,
        }
    }
}

/// Progress reporting plus the CSV history.
pub struct SolveLog {
    verbosity: Verbosity,
    bar: Option<ProgressBar>,
    csv: String,
}

impl SolveLog {
    pub const CSV_HEADER: &'static str = "increment,load_factor,attempt,augmentation,iteration,residual,energy,contact_active,seconds_contact,seconds_assembly,seconds_factor,seconds_solve,krylov_iterations\n";

    pub fn new(verbosity: Verbosity, n_increments: usize) -> Self {
        let bar = (verbosity == Verbosity::Normal && std::io::stderr().is_terminal()).then(|| {
            let b = ProgressBar::new(n_increments as u64);
            b.set_style(ProgressStyle::with_template("{elapsed_precise} [{bar:30}] increment {pos}/{len} {msg}").expect("valid template").progress_chars("=> "));
            b
        });
        Self { verbosity, bar, csv: Self::CSV_HEADER.to_string() }
    }

    /// A message line (shown above the bar on a terminal).
    pub fn line(&self, text: &str) {
        if self.verbosity != Verbosity::Normal {
            return;
        }
        self.print(text);
    }

    /// A warning: printed as `warning: <text>` even when quiet, since it says the
    /// answer is not what was asked for (penetration above tolerance, nodes left out).
    pub fn warning(&self, text: &str) {
        if self.verbosity == Verbosity::Silent {
            return;
        }
        self.print(&format!("warning: {text}"));
    }

    fn print(&self, text: &str) {
        match &self.bar {
            Some(b) => b.println(text),
            None => {
                let _ = writeln!(std::io::stderr(), "{text}");
            }
        }
    }

    pub fn iteration(&mut self, e: &IterationEvent) {
        self.push_csv(e);
        let text = format!(
            "increment {}/{} (λ = {:.4}{}{}) iteration {:>2}: residual {:.3e}, energy {:.3e}{}",
            e.increment,
            e.n_increments,
            e.load_factor,
            if e.attempt > 0 { format!(", cutback {}", e.attempt) } else { String::new() },
            if e.augmentation > 0 { format!(", augmentation {}", e.augmentation) } else { String::new() },
            e.iteration,
            e.residual,
            e.energy,
            if e.seconds_contact > 0.0 { format!(", {} contact nodes pressed", e.contact_active) } else { String::new() }
        );
        match &self.bar {
            Some(b) => b.set_message(text),
            None => self.line(&text),
        }
    }

    /// The iterations of an increment read back from a results file (a restart):
    /// its converged attempt, numbered `increment` of the load path; the attempts cut
    /// back before it are not in the file. Only the CSV gets them.
    pub fn restored(&mut self, increment: usize, n_increments: usize, info: &IncrementInfo) {
        for row in &info.iterations {
            self.push_csv(&IterationEvent::from_row(increment, n_increments, info.load_factor, info.cutbacks, row));
        }
        if let Some(b) = &self.bar {
            b.set_position(increment as u64);
        }
    }

    pub fn increment_done(&self) {
        if let Some(b) = &self.bar {
            b.inc(1);
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }

    fn push_csv(&mut self, e: &IterationEvent) {
        self.csv.push_str(&format!(
            "{},{:e},{},{},{},{:e},{:e},{},{:.6},{:.6},{:.6},{:.6},{}\n",
            e.increment,
            e.load_factor,
            e.attempt,
            e.augmentation,
            e.iteration,
            e.residual,
            e.energy,
            e.contact_active,
            e.seconds_contact,
            e.seconds_assembly,
            e.seconds_factor,
            e.seconds_solve,
            e.krylov_iterations
        ));
    }

    /// The convergence history so far, as CSV text.
    pub fn csv(&self) -> &str {
        &self.csv
    }
}
