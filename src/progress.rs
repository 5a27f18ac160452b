//! What a run reports while it works: the step starting, and inside the elastic solve the
//! assembly fraction, the set-up and each CG iteration, each with a message and (where it
//! means something) the fraction done, for a spinner or a bar.

use hocurve_elastic::{SolveProgress, SolverKind};

/// A step of the pipeline, announced to the progress callback before it runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// Placing the order-p nodes on the straight elements.
    HighOrderNodes,
    /// Associating boundary facets with geometry entities.
    Association,
    /// Placing boundary nodes on the geometry.
    BoundaryNodes,
    /// Assembling and solving the elasticity problem.
    Elasticity,
    /// Measuring the curved mesh.
    Quality,
    /// Repairing the elements not certified valid.
    Repair,
    /// Splitting the longest chords of elements no repair certified, to curve again.
    Refinement,
    /// Writing the outputs (the caller's step, see [`crate::job`]).
    Writing,
}

impl Step {
    /// What the step does, for progress messages.
    pub fn describe(self) -> &'static str {
        match self {
            Step::HighOrderNodes => "placing high-order nodes",
            Step::Repair => "repairing elements not certified valid",
            Step::Refinement => "splitting edges of elements not certified, curving again",
            Step::Writing => "writing the mesh",
            Step::Association => "associating the boundary with the geometry",
            Step::BoundaryNodes => "placing boundary nodes on the geometry",
            Step::Elasticity => "solving linear elasticity",
            Step::Quality => "measuring quality",
        }
    }
}

/// What [`crate::pipeline::curve_mesh`] reports while it runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Progress {
    /// A step starts.
    Step(Step),
    /// Progress inside the elasticity step (assembly fraction, set-up, CG iterations).
    Elasticity(SolveProgress),
}

impl Progress {
    /// A message for the user and the fraction of the step done (None: a spinner), e.g.
    /// "CG iteration 12, residual 3.1e-7" at the orders of magnitude of residual reduction
    /// gained towards the tolerance.
    pub fn status(&self) -> (String, Option<f64>) {
        match *self {
            Progress::Step(step) => (step.describe().to_string(), None),
            Progress::Elasticity(SolveProgress::Assembly { fraction }) => (
                "assembling the stiffness matrix".to_string(),
                Some(fraction),
            ),
            Progress::Elasticity(SolveProgress::Setup { solver, dofs }) => (
                match solver {
                    SolverKind::Direct => {
                        format!("factorising the stiffness matrix ({dofs} unknowns)")
                    }
                    _ => format!("setting up the p-multigrid preconditioner ({dofs} unknowns)"),
                },
                None,
            ),
            Progress::Elasticity(SolveProgress::Iteration {
                iteration,
                relative_residual,
                tolerance,
            }) => {
                let gained = relative_residual.log10() / tolerance.log10();
                (
                    format!("CG iteration {iteration}, residual {relative_residual:.1e}"),
                    Some(if gained.is_finite() { gained } else { 0.0 }),
                )
            }
        }
    }
}
