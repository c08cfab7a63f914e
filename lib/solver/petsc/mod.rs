//! The PETSc backend of [`LinearSolver`]: Krylov (CG for a symmetric tangent,
//! GMRES for the frictional one) preconditioned by smoothed-aggregation algebraic
//! multigrid (GAMG) with the rigid-body near-null space, under MPI when the
//! program runs under `mpirun` (cargo feature `petsc`).
//!
//! **Why.** A direct factorization's fill grows like N^{4/3} on 3D meshes: the
//! crossed beams at 1M dofs would need about 25 GB. AMG needs O(N) memory and
//! nearly size-independent iteration counts (`docs/performance.md`).
//!
//! **The matrix.** AIJ with block size 3 over the full `3n` system
//! ([`super::block_rows`]: constrained rows are `d·I`), each rank owning a
//! contiguous range of nodes ([`super::ranks::owned_nodes`]) and inserting only
//! those block rows. Under MPI each rank's Newton assembles every element that
//! touches its nodes (`newton::partition::Partition`), so its rows are complete and nothing is
//! shipped at assembly. GAMG rejects block-AIJ (BAIJ) in PETSc 3.18; AIJ with block
//! size 3 still gets node aggregation and inode kernels.
//!
//! **Collective calls.** Every PETSc call here is collective under MPI, so every
//! branch before one is decided by all ranks together (the indefinite check and the
//! non-finite check reduce over ranks); a branch taken by one rank alone deadlocks.
//!
//! **Near-null space.** The six rigid-body modes at the current nodal coordinates
//! (`MatNullSpaceCreateRigidBody`), rebuilt with the hierarchy. Without them GAMG
//! needs 3–5× the iterations on these tangents.
//!
//! **Reuse.** The hierarchy of one Newton iteration serves the next ones
//! (`KSPSetReusePreconditioner`) while a solve needs at most `reuse_growth` times
//! the iterations it needed right after it was built (and a few more); then it is
//! rebuilt. (The iteration counts are the same on every rank.) A new pattern (the contact groups changed) rebuilds the matrix and the
//! hierarchy. `-pc_gamg_reuse_interpolation` keeps GAMG's aggregates across
//! rebuilds on one pattern.
//!
//! **An indefinite tangent.** The Newton iterate after first contact overshoots
//! (the body goes through its master), and the tangent there has non-positive
//! diagonal entries, from which smoothed aggregation builds no usable hierarchy.
//! Neither a hierarchy built from a repaired copy (diagonal `max(|a_ii|, d)`) for
//! GMRES on the true tangent, nor GMRES on the repaired tangent itself (a modified
//! Newton step) converged in 500 iterations on the crossed beams at 109k dofs, so
//! such a tangent goes straight to the direct fallback, and the next iteration
//! builds a fresh hierarchy.
//!
//! **Fallback.** An indefinite tangent, or a Krylov solve that fails, goes to a
//! direct solve by MUMPS
//! through PETSc (Cholesky for a symmetric tangent, LU otherwise; prefix
//! `fallback_` for its options; its factors are freed after the solve), and the log
//! says so, on systems up to `direct_fallback_max_dofs` (300k: MUMPS's LU of the
//! crossed beams at 1M dofs needs more than 19 GB). Above it the solve fails and
//! Newton cuts the load step back, which at first contact is what helps: the
//! smaller step overshoots less.
//!
//! **Options.** Defaults are set first, then the setup's `petsc.options`, then the
//! command line's `--petsc-options` (later ones win): any PETSc option, e.g.
//! `-ksp_type bcgs`, `-pc_type hypre`, `-ksp_monitor`.

mod ffi;
pub mod runtime;

use std::ffi::{c_int, CString};
use std::time::Instant;

use faer::sparse::SymbolicSparseColMatRef;
use nalgebra::Vector3;

use self::ffi::*;
use super::block_rows::BlockRows;
use super::linear::{FactorInfo, Factorization, LinearSolver, LinearSolverError, SolveReport, SolverTimings, Symmetry};
use super::ranks::owned_nodes;
pub use runtime::{finalize, initialize, PetscError};

/// Settings of [`PetscKrylov`].
#[derive(Debug, Clone, PartialEq)]
pub struct PetscSettings {
    /// PETSc options, applied after the defaults (`-ksp_type bcgs -pc_type hypre`).
    pub options: String,
    /// Relative residual ‖b − K x‖/‖b‖ at which a solve stops, unless an inexact
    /// Newton's forcing term is larger.
    pub tolerance: f64,
    /// Most Krylov iterations per solve before the direct fallback.
    pub max_iterations: usize,
    /// Rebuild the hierarchy when a solve needs more than `reuse_growth ×` (+5) the
    /// iterations of the first solve after the last rebuild; `0`: rebuild every
    /// Newton iteration.
    pub reuse_growth: f64,
    /// Largest system (dofs, held ones included) the MUMPS fallback may factor;
    /// above it a solve that needs the fallback fails, and Newton cuts the load step
    /// back (a smaller step overshoots less at first contact).
    pub direct_fallback_max_dofs: usize,
}

impl Default for PetscSettings {
    fn default() -> Self {
        Self { options: String::new(), tolerance: 1e-10, max_iterations: 500, reuse_growth: 1.5, direct_fallback_max_dofs: 300_000 }
    }
}

/// Options every solve starts from (the user's come after and win).
const DEFAULT_OPTIONS: &str = "-pc_gamg_threshold 0.05 -pc_gamg_reuse_interpolation true -fallback_mat_mumps_icntl_14 100";

fn check(function: &'static str, code: PetscErrorCode) -> Result<(), LinearSolverError> {
    if code == 0 {
        Ok(())
    } else {
        Err(LinearSolverError::Backend(runtime::describe(function, code)))
    }
}

fn cstr(s: &str) -> CString {
    CString::new(s).expect("PETSc type names have no NUL")
}

/// The Krylov + AMG backend.
pub struct PetscKrylov {
    settings: PetscSettings,
    global_of_free: Vec<u32>,
    n_nodes: usize,
    /// Nodes this rank owns, `first..last`.
    owned: (usize, usize),
    symmetry: Symmetry,
    rows: Option<BlockRows>,
    block_values: Vec<f64>,
    /// Current coordinates of the owned nodes (3 per node), for the near-null space.
    coordinates: Vec<f64>,
    mat: Mat,
    b: Vec_,
    x: Vec_,
    scatter: VecScatter,
    x_all: Vec_,
    ksp: Ksp,
    fallback: Ksp,
    /// The hierarchy must be rebuilt at the next `factor`.
    rebuild: bool,
    /// Iterations of the first solve after the last rebuild.
    base_iterations: Option<usize>,
    last_iterations: usize,
    /// Scratch: the global dofs of the last factored matrix's non-positive free
    /// diagonal entries.
    non_positive: Vec<usize>,
    /// Their number in this rank's rows, summed over all ranks (0: definite).
    indefinite_total: usize,
    eta: f64,
    report: SolveReport,
    timings: SolverTimings,
}

// The handles are only touched under runtime::LOCK, by the thread that owns the solver.
unsafe impl Send for PetscKrylov {}

impl PetscKrylov {
    /// A solver for the free dofs `global_of_free` of `n_nodes` nodes. Starts PETSc
    /// (and MPI) if the program has not.
    pub fn new(settings: PetscSettings, global_of_free: &[u32], n_nodes: usize) -> Result<Self, LinearSolverError> {
        initialize().map_err(|e| LinearSolverError::Backend(e.to_string()))?;
        let owned = owned_nodes(n_nodes);
        Ok(Self {
            settings,
            global_of_free: global_of_free.to_vec(),
            n_nodes,
            owned,
            symmetry: Symmetry::General,
            rows: None,
            block_values: Vec::new(),
            coordinates: Vec::new(),
            mat: Handle::NULL,
            b: Handle::NULL,
            x: Handle::NULL,
            scatter: Handle::NULL,
            x_all: Handle::NULL,
            ksp: Handle::NULL,
            fallback: Handle::NULL,
            rebuild: true,
            base_iterations: None,
            last_iterations: 0,
            non_positive: Vec::new(),
            indefinite_total: 0,
            eta: 0.0,
            report: SolveReport::default(),
            timings: SolverTimings::default(),
        })
    }

    /// Destroys every PETSc object (before a new pattern, and on drop).
    fn release(&mut self) {
        unsafe {
            if !self.ksp.is_null() {
                KSPDestroy(&mut self.ksp);
            }
            if !self.fallback.is_null() {
                KSPDestroy(&mut self.fallback);
            }
            if !self.scatter.is_null() {
                VecScatterDestroy(&mut self.scatter);
            }
            for v in [&mut self.b, &mut self.x, &mut self.x_all] {
                if !v.is_null() {
                    VecDestroy(v);
                }
            }
            if !self.mat.is_null() {
                MatDestroy(&mut self.mat);
            }
        }
        self.ksp = Handle::NULL;
        self.fallback = Handle::NULL;
        self.scatter = Handle::NULL;
        self.b = Handle::NULL;
        self.x = Handle::NULL;
        self.x_all = Handle::NULL;
        self.mat = Handle::NULL;
    }

    fn create_matrix(&mut self) -> Result<(), LinearSolverError> {
        let rows = self.rows.as_ref().ok_or(LinearSolverError::Order("factor", "analyse"))?;
        let (first, last) = self.owned;
        let (mut d_nnz, mut o_nnz) = (Vec::with_capacity(last - first), Vec::with_capacity(last - first));
        for i in first..last {
            let (cols, _) = rows.row(i);
            let inside = cols.iter().filter(|&&c| (c as usize) >= first && (c as usize) < last).count();
            d_nnz.push(inside as PetscInt);
            o_nnz.push((cols.len() - inside) as PetscInt);
        }
        let local = (3 * (last - first)) as PetscInt;
        let global = (3 * self.n_nodes) as PetscInt;
        unsafe {
            check("MatCreate", sc_mat_create(&mut self.mat))?;
            check("MatSetSizes", MatSetSizes(self.mat, local, local, global, global))?;
            check("MatSetBlockSize", MatSetBlockSize(self.mat, 3))?;
            check("MatSetType", MatSetType(self.mat, cstr("aij").as_ptr()))?;
            check("MatXAIJSetPreallocation", MatXAIJSetPreallocation(self.mat, 3, d_nnz.as_ptr(), o_nnz.as_ptr(), std::ptr::null(), std::ptr::null()))?;
            check("MatSetOption", MatSetOption(self.mat, sc_MAT_NEW_NONZERO_ALLOCATION_ERR, sc_PETSC_TRUE))?;
            check("MatCreateVecs", MatCreateVecs(self.mat, &mut self.x, &mut self.b))?;
            check("VecScatterCreateToAll", VecScatterCreateToAll(self.x, &mut self.scatter, &mut self.x_all))?;
        }
        Ok(())
    }

    fn create_ksp(&mut self) -> Result<(), LinearSolverError> {
        let symmetric = self.symmetry == Symmetry::Symmetric;
        unsafe {
            check("PetscOptionsInsertString", PetscOptionsInsertString(std::ptr::null_mut(), cstr(DEFAULT_OPTIONS).as_ptr()))?;
            if !self.settings.options.trim().is_empty() {
                let user = CString::new(self.settings.options.as_str())
                    .map_err(|_| LinearSolverError::Backend("petsc.options contains a NUL character".into()))?;
                check("PetscOptionsInsertString", PetscOptionsInsertString(std::ptr::null_mut(), user.as_ptr()))?;
            }
            check("KSPCreate", sc_ksp_create(&mut self.ksp))?;
            check("KSPSetOperators", KSPSetOperators(self.ksp, self.mat, self.mat))?;
            check("KSPSetType", KSPSetType(self.ksp, cstr(if symmetric { "cg" } else { "gmres" }).as_ptr()))?;
            if !symmetric {
                check("KSPGMRESSetRestart", KSPGMRESSetRestart(self.ksp, 100))?;
                check("KSPSetPCSide", KSPSetPCSide(self.ksp, sc_PC_RIGHT))?;
            }
            check("KSPSetNormType", KSPSetNormType(self.ksp, sc_KSP_NORM_UNPRECONDITIONED))?;
            let mut pc = Handle::NULL;
            check("KSPGetPC", KSPGetPC(self.ksp, &mut pc))?;
            check("PCSetType", PCSetType(pc, cstr("gamg").as_ptr()))?;
            check("KSPSetFromOptions", KSPSetFromOptions(self.ksp))?;
        }
        Ok(())
    }

    /// The rigid-body modes at the current coordinates, attached to the matrix.
    fn attach_near_null_space(&mut self) -> Result<(), LinearSolverError> {
        let (first, last) = self.owned;
        if self.coordinates.len() != 3 * (last - first) {
            return Ok(()); // no coordinates given: GAMG's default (constant) modes
        }
        unsafe {
            let mut coords = Handle::NULL;
            check("VecDuplicate", VecDuplicate(self.x, &mut coords))?;
            let mut a: *mut f64 = std::ptr::null_mut();
            check("VecGetArray", VecGetArray(coords, &mut a))?;
            std::slice::from_raw_parts_mut(a, self.coordinates.len()).copy_from_slice(&self.coordinates);
            check("VecRestoreArray", VecRestoreArray(coords, &mut a))?;
            let mut space = Handle::NULL;
            let made = check("MatNullSpaceCreateRigidBody", MatNullSpaceCreateRigidBody(coords, &mut space));
            VecDestroy(&mut coords);
            made?;
            let set = check("MatSetNearNullSpace", MatSetNearNullSpace(self.mat, space));
            MatNullSpaceDestroy(&mut space);
            set
        }
    }

    /// Direct solve of `b` into `x` by MUMPS through PETSc.
    fn solve_direct(&mut self, why: &str) -> Result<(), LinearSolverError> {
        let n = 3 * self.n_nodes;
        if n > self.settings.direct_fallback_max_dofs {
            return Err(LinearSolverError::Backend(format!(
                "{why}, and {n} dofs are beyond the MUMPS fallback's limit (petsc.direct_fallback_max_dofs = {})",
                self.settings.direct_fallback_max_dofs
            )));
        }
        unsafe {
            if self.fallback.is_null() {
                let symmetric = self.symmetry == Symmetry::Symmetric;
                check("KSPCreate", sc_ksp_create(&mut self.fallback))?;
                check("KSPSetOptionsPrefix", KSPSetOptionsPrefix(self.fallback, cstr("fallback_").as_ptr()))?;
                check("KSPSetOperators", KSPSetOperators(self.fallback, self.mat, self.mat))?;
                check("KSPSetType", KSPSetType(self.fallback, cstr("preonly").as_ptr()))?;
                let mut pc = Handle::NULL;
                check("KSPGetPC", KSPGetPC(self.fallback, &mut pc))?;
                // LDLᵀ for symmetric (the indefinite first-contact tangent included)
                check("PCSetType", PCSetType(pc, cstr(if symmetric { "cholesky" } else { "lu" }).as_ptr()))?;
                check("PCFactorSetMatSolverType", PCFactorSetMatSolverType(pc, cstr("mumps").as_ptr()))?;
                check("KSPSetFromOptions", KSPSetFromOptions(self.fallback))?;
            }
            check("KSPSetUp", KSPSetUp(self.fallback))?;
            check("KSPSolve", KSPSolve(self.fallback, self.b, self.x))?;
            let mut reason: c_int = 0;
            check("KSPGetConvergedReason", KSPGetConvergedReason(self.fallback, &mut reason))?;
            // its factors go: at the sizes this backend is for they are the largest
            // thing in memory, and the next fallback has another matrix anyway
            KSPDestroy(&mut self.fallback);
            self.fallback = Handle::NULL;
            if reason < 0 {
                return Err(LinearSolverError::Backend(format!("the MUMPS fallback failed (KSPConvergedReason {reason})")));
            }
        }
        self.timings.n_fallback += 1;
        Ok(())
    }
}

impl Drop for PetscKrylov {
    fn drop(&mut self) {
        let _guard = runtime::LOCK.lock().unwrap_or_else(|p| p.into_inner());
        self.release();
    }
}

impl LinearSolver for PetscKrylov {
    fn name(&self) -> &str {
        "petsc-gamg"
    }

    fn analyse(&mut self, pattern: SymbolicSparseColMatRef<'_, usize>, symmetry: Symmetry) -> Result<(), LinearSolverError> {
        let start = Instant::now();
        let _guard = runtime::LOCK.lock().unwrap_or_else(|p| p.into_inner());
        self.release();
        self.rows = None;
        self.block_values = Vec::new();
        let rows = BlockRows::new(pattern, &self.global_of_free, self.n_nodes).map_err(|e| LinearSolverError::Backend(e.to_string()))?;
        self.block_values = vec![0.0; 9 * rows.n_blocks()];
        self.rows = Some(rows);
        self.symmetry = symmetry;
        self.create_matrix()?;
        // the Krylov solver now, so that a bad option is reported before the first solve
        self.create_ksp()?;
        self.rebuild = true;
        self.base_iterations = None;
        self.timings.symbolic += start.elapsed();
        self.timings.n_symbolic += 1;
        Ok(())
    }

    fn factor(&mut self, values: &[f64]) -> Result<FactorInfo, LinearSolverError> {
        let start = Instant::now();
        let _guard = runtime::LOCK.lock().unwrap_or_else(|p| p.into_inner());
        let Some(rows) = self.rows.as_ref() else {
            return Err(LinearSolverError::Order("factor", "analyse"));
        };
        // a non-finite value stops every rank (the calls that follow are collective)
        let bad = values.iter().position(|v| !v.is_finite());
        let mut any_bad = [f64::from(u8::from(bad.is_some()))];
        runtime::max_over_ranks(&mut any_bad).map_err(|e| LinearSolverError::Backend(e.to_string()))?;
        if any_bad[0] > 0.0 {
            return Err(match bad {
                Some(index) => LinearSolverError::NonFinite { index },
                None => LinearSolverError::Backend("another MPI rank's tangent has a non-finite value".into()),
            });
        }
        rows.scatter(values, &mut self.block_values, &mut self.non_positive);
        let (first, last) = self.owned;
        // only this rank's rows are complete (and inserted); whether the tangent is
        // indefinite is decided by all ranks together, as what follows is collective
        let mut count = [self.non_positive.iter().filter(|&&g| g >= 3 * first && g < 3 * last).count() as f64];
        runtime::sum_over_ranks(&mut count).map_err(|e| LinearSolverError::Backend(e.to_string()))?;
        self.indefinite_total = count[0] as usize;
        unsafe {
            for i in first..last {
                let (cols, offset) = rows.row(i);
                let row = i as PetscInt;
                check(
                    "MatSetValuesBlocked",
                    MatSetValuesBlocked(self.mat, 1, &row, cols.len() as PetscInt, cols.as_ptr(), self.block_values[offset..].as_ptr(), sc_INSERT_VALUES),
                )?;
            }
            check("MatAssemblyBegin", MatAssemblyBegin(self.mat, sc_MAT_FINAL_ASSEMBLY))?;
            check("MatAssemblyEnd", MatAssemblyEnd(self.mat, sc_MAT_FINAL_ASSEMBLY))?;
            let symmetric = if self.symmetry == Symmetry::Symmetric { sc_PETSC_TRUE } else { sc_PETSC_FALSE };
            check("MatSetOption", MatSetOption(self.mat, sc_MAT_SYMMETRIC, symmetric))?;
        }
        // keep the hierarchy while the iterations stay near those of its first solve
        if let Some(base) = self.base_iterations {
            let limit = (self.settings.reuse_growth * base as f64) as usize + 5;
            if self.settings.reuse_growth <= 0.0 || self.last_iterations > limit {
                self.rebuild = true;
            }
        }
        let reuse = !self.rebuild && self.indefinite_total == 0;
        unsafe {
            check("KSPSetReusePreconditioner", KSPSetReusePreconditioner(self.ksp, if reuse { sc_PETSC_TRUE } else { sc_PETSC_FALSE }))?;
        }
        if reuse {
            self.timings.n_reused += 1;
        } else if self.indefinite_total == 0 {
            self.attach_near_null_space()?;
            unsafe { check("KSPSetUp", KSPSetUp(self.ksp))? };
            self.rebuild = false;
            self.base_iterations = None;
        }
        let time = start.elapsed();
        self.timings.numeric += time;
        self.timings.n_numeric += 1;
        Ok(FactorInfo { method: Factorization::Multigrid, time })
    }

    fn solve_in_place(&mut self, _values: &[f64], rhs: &mut [f64]) -> Result<(), LinearSolverError> {
        let start = Instant::now();
        let _guard = runtime::LOCK.lock().unwrap_or_else(|p| p.into_inner());
        if self.mat.is_null() || self.ksp.is_null() {
            return Err(LinearSolverError::Order("solve", "factor"));
        }
        if rhs.len() != self.global_of_free.len() {
            return Err(LinearSolverError::Dimension { what: "right-hand side entries", expected: self.global_of_free.len(), got: rhs.len() });
        }
        let (first, last) = self.owned;
        unsafe {
            let mut a: *mut f64 = std::ptr::null_mut();
            check("VecGetArray", VecGetArray(self.b, &mut a))?;
            let local = std::slice::from_raw_parts_mut(a, 3 * (last - first));
            local.iter_mut().for_each(|v| *v = 0.0);
            // free dofs are increasing in global order: the owned ones are a range
            let lo = self.global_of_free.partition_point(|&g| (g as usize) < 3 * first);
            let hi = self.global_of_free.partition_point(|&g| (g as usize) < 3 * last);
            for f in lo..hi {
                local[self.global_of_free[f] as usize - 3 * first] = rhs[f];
            }
            check("VecRestoreArray", VecRestoreArray(self.b, &mut a))?;
        }
        self.report = SolveReport::default();
        let mut iterations = 0;
        if self.indefinite_total > 0 {
            let why = format!(
                "the tangent has {} non-positive diagonal entries (indefinite, as after a Newton overshoot), from which multigrid builds no usable hierarchy",
                self.indefinite_total
            );
            self.rebuild = true;
            self.solve_direct(&why)?;
            self.report.fallback = Some(format!("{why}: solved by MUMPS (direct) instead"));
        } else {
            let rtol = self.eta.max(self.settings.tolerance);
            let mut reason: c_int = 0;
            let mut its: PetscInt = 0;
            unsafe {
                check("KSPSetTolerances", KSPSetTolerances(self.ksp, rtol, 1e-300, sc_PETSC_DEFAULT as f64, self.settings.max_iterations as PetscInt))?;
                check("KSPSolve", KSPSolve(self.ksp, self.b, self.x))?;
                check("KSPGetConvergedReason", KSPGetConvergedReason(self.ksp, &mut reason))?;
                check("KSPGetIterationNumber", KSPGetIterationNumber(self.ksp, &mut its))?;
            }
            iterations = its as usize;
            self.timings.n_krylov += iterations;
            self.last_iterations = iterations;
            if self.base_iterations.is_none() {
                self.base_iterations = Some(iterations);
            }
            if reason < 0 {
                let why = format!("the Krylov solve stopped after {iterations} iterations ({})", runtime::converged_reason(reason));
                self.rebuild = true;
                self.solve_direct(&why)?;
                self.report.fallback = Some(format!("{why}: solved by MUMPS (direct) instead"));
            }
        }
        self.report.krylov_iterations = iterations;
        unsafe {
            check("VecScatterBegin", VecScatterBegin(self.scatter, self.x, self.x_all, sc_INSERT_VALUES, sc_SCATTER_FORWARD))?;
            check("VecScatterEnd", VecScatterEnd(self.scatter, self.x, self.x_all, sc_INSERT_VALUES, sc_SCATTER_FORWARD))?;
            let mut a: *const f64 = std::ptr::null();
            check("VecGetArrayRead", VecGetArrayRead(self.x_all, &mut a))?;
            let all = std::slice::from_raw_parts(a, 3 * self.n_nodes);
            for (r, &g) in rhs.iter_mut().zip(&self.global_of_free) {
                *r = all[g as usize];
            }
            check("VecRestoreArrayRead", VecRestoreArrayRead(self.x_all, &mut a))?;
        }
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolverError::Singular { dof: None });
        }
        self.timings.solve += start.elapsed();
        self.timings.n_solve += 1;
        Ok(())
    }

    fn timings(&self) -> SolverTimings {
        self.timings
    }

    fn last_solve(&self) -> SolveReport {
        self.report.clone()
    }

    fn set_forcing(&mut self, eta: f64) {
        self.eta = eta;
    }

    fn set_configuration(&mut self, reference: &[Vector3<f64>], u: &[f64]) {
        let (first, last) = self.owned;
        self.coordinates.clear();
        for a in first..last.min(reference.len()) {
            for i in 0..3 {
                self.coordinates.push(reference[a][i] + u.get(3 * a + i).copied().unwrap_or(0.0));
            }
        }
    }
}

/// The PETSc version the program was built against, `[major, minor, subminor]`.
pub fn version() -> [i32; 3] {
    unsafe { sc_petsc_version }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::bench::{elastic_cube_system, relative_residual};

    fn cube_solver(n: usize, settings: PetscSettings) -> (crate::solver::bench::ElasticCube, PetscKrylov) {
        let cube = elastic_cube_system(n).unwrap();
        let n_nodes = cube.pattern.dofs().n_nodes();
        let s = PetscKrylov::new(settings, cube.pattern.dofs().global_of_free(), n_nodes).unwrap();
        (cube, s)
    }

    /// The clamped cube (with every node's rigid-body coordinates): CG + GAMG reaches
    /// the requested relative residual, checked with our own product (not PETSc's
    /// estimate), and needs few iterations with the near-null space.
    #[test]
    fn cg_with_gamg_solves_the_clamped_cube_to_its_tolerance() {
        let (cube, mut s) = cube_solver(6, PetscSettings { tolerance: 1e-9, ..Default::default() });
        let n_nodes = cube.pattern.dofs().n_nodes();
        let (nodes, _) = crate::assembly::pattern::structured_hex_grid(6, 6, 6);
        let reference: Vec<Vector3<f64>> = nodes.iter().map(|x| Vector3::new(x[0], x[1], x[2])).collect();
        assert_eq!(reference.len(), n_nodes);
        s.set_configuration(&reference, &vec![0.0; 3 * n_nodes]);
        let p = &cube.pattern;
        s.analyse(p.symbolic(), Symmetry::Symmetric).unwrap();
        assert_eq!(s.factor(cube.assembly.values()).unwrap().method, Factorization::Multigrid);
        let mut x = cube.rhs.clone();
        s.solve_in_place(cube.assembly.values(), &mut x).unwrap();
        let r = relative_residual(p.col_ptr(), p.row_idx(), cube.assembly.values(), &x, &cube.rhs);
        let its = s.last_solve().krylov_iterations;
        // CG's recurrence residual vs the true one: agree to a few ulps × condition
        assert!(r <= 2e-9, "relative residual {r:e} after {its} iterations");
        assert!(its > 0 && its <= 40, "{its} iterations");
        assert!(s.last_solve().fallback.is_none());
        // the next factor keeps the hierarchy (same values: same iterations)
        s.factor(cube.assembly.values()).unwrap();
        let mut y = cube.rhs.clone();
        s.solve_in_place(cube.assembly.values(), &mut y).unwrap();
        assert_eq!(s.timings().n_reused, 1);
        assert!(s.last_solve().krylov_iterations <= its + 1);
    }

    /// A non-positive diagonal (the indefinite tangent after a Newton overshoot)
    /// skips multigrid: MUMPS solves it, the report says so, its factors are freed,
    /// and the next factor builds a hierarchy.
    #[test]
    fn an_indefinite_tangent_goes_to_the_direct_fallback() {
        let (cube, mut s) = cube_solver(3, PetscSettings::default());
        let p = &cube.pattern;
        let mut values = cube.assembly.values().to_vec();
        for j in [0, 10] {
            let k = (p.col_ptr()[j]..p.col_ptr()[j + 1]).find(|&k| p.row_idx()[k] == j).unwrap();
            values[k] = -values[k];
        }
        s.analyse(p.symbolic(), Symmetry::General).unwrap();
        s.factor(&values).unwrap();
        let mut x = cube.rhs.clone();
        s.solve_in_place(&values, &mut x).unwrap();
        let why = s.last_solve().fallback.expect("fallback reported");
        assert!(why.contains("2 non-positive diagonal entries") && why.contains("MUMPS"), "{why}");
        let r = relative_residual(p.col_ptr(), p.row_idx(), &values, &x, &cube.rhs);
        assert!(r <= 1e-10, "MUMPS residual {r:e}");
        assert!(s.fallback.is_null(), "the MUMPS factors are freed");
        s.factor(cube.assembly.values()).unwrap();
        let mut y = cube.rhs.clone();
        s.solve_in_place(cube.assembly.values(), &mut y).unwrap();
        assert!(s.last_solve().fallback.is_none() && s.last_solve().krylov_iterations > 0);
        assert_eq!(s.timings().n_fallback, 1);
        // above the fallback's size limit the solve fails (Newton then cuts back)
        s.settings.direct_fallback_max_dofs = 10;
        s.factor(&values).unwrap();
        let e = s.solve_in_place(&values, &mut cube.rhs.clone()).unwrap_err().to_string();
        assert!(e.contains("non-positive diagonal") && e.contains("direct_fallback_max_dofs = 10"), "{e}");
    }

    /// A Krylov solve that cannot finish in its budget falls back, and says why.
    #[test]
    fn a_krylov_solve_out_of_iterations_goes_to_the_direct_fallback() {
        let (cube, mut s) = cube_solver(4, PetscSettings { max_iterations: 2, tolerance: 1e-12, ..Default::default() });
        let p = &cube.pattern;
        s.analyse(p.symbolic(), Symmetry::General).unwrap();
        s.factor(cube.assembly.values()).unwrap();
        let mut x = cube.rhs.clone();
        s.solve_in_place(cube.assembly.values(), &mut x).unwrap();
        let why = s.last_solve().fallback.expect("fallback reported");
        assert!(why.contains("2 iterations") && why.contains("KSP_DIVERGED_ITS"), "{why}");
        assert!(relative_residual(p.col_ptr(), p.row_idx(), cube.assembly.values(), &x, &cube.rhs) <= 1e-10);
    }
}
