//! Starting and stopping PETSc (and MPI), and the program's own MPI messages.
//!
//! PETSc starts once per process, on first use ([`initialize`]); a program that
//! runs under `mpirun` should start it before it reads anything, so every rank
//! agrees on its rank from the start, and call [`finalize`] before it exits.

use std::ffi::{c_int, CStr};
use std::sync::{Mutex, OnceLock};

use super::ffi::*;

/// Every PETSc call of the process goes through this lock: PETSc's global state
/// (options, logging, memory tracking) is not thread-safe, and tests run solvers on
/// several threads.
pub(super) static LOCK: Mutex<()> = Mutex::new(());

/// A PETSc call that failed: the function, PETSc's code and its message.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct PetscError(pub String);

static STARTED: OnceLock<Result<(), PetscError>> = OnceLock::new();

/// Starts PETSc and MPI (once; later calls return the first result).
pub fn initialize() -> Result<(), PetscError> {
    STARTED
        .get_or_init(|| {
            let _guard = LOCK.lock().unwrap_or_else(|p| p.into_inner());
            let code = unsafe { sc_initialize() };
            if code != 0 {
                return Err(PetscError(describe("PetscInitialize", code)));
            }
            let (int, scalar) = unsafe { (sc_sizeof_petsc_int, sc_sizeof_petsc_scalar) };
            if int != 4 || scalar != 8 {
                return Err(PetscError(format!("PETSc was built with {int}-byte PetscInt and {scalar}-byte PetscScalar; this build expects 4 and 8")));
            }
            Ok(())
        })
        .clone()
}

/// Whether PETSc has been started in this process.
pub fn is_initialized() -> bool {
    matches!(STARTED.get(), Some(Ok(())))
}

/// Stops PETSc and MPI (the program's last PETSc call; nothing may follow).
pub fn finalize() {
    if is_initialized() {
        let _guard = LOCK.lock().unwrap_or_else(|p| p.into_inner());
        unsafe {
            PetscFinalize();
        }
    }
}

/// This process's rank and the number of ranks (`(0, 1)` before [`initialize`]).
pub fn rank_and_size() -> (usize, usize) {
    if !is_initialized() {
        return (0, 1);
    }
    unsafe { (sc_comm_rank().max(0) as usize, sc_comm_size().max(1) as usize) }
}

/// Sums `x` over all ranks, entry by entry, in place.
pub fn sum_over_ranks(x: &mut [f64]) -> Result<(), PetscError> {
    all_reduce(x, sc_allreduce_sum_f64)
}

/// The largest value of each entry of `x` over all ranks, in place.
pub fn max_over_ranks(x: &mut [f64]) -> Result<(), PetscError> {
    all_reduce(x, sc_allreduce_max_f64)
}

/// `MPI_Allreduce` of `x` in place by one of the shim's reductions.
fn all_reduce(x: &mut [f64], reduce: unsafe extern "C" fn(*mut f64, c_int) -> c_int) -> Result<(), PetscError> {
    if x.is_empty() || rank_and_size().1 == 1 {
        return Ok(());
    }
    let (ptr, n) = (x.as_mut_ptr(), x.len() as c_int);
    let code = unsafe { reduce(ptr, n) };
    if code != 0 {
        return Err(PetscError(format!("MPI_Allreduce failed with code {code}")));
    }
    Ok(())
}

/// "`function`: PETSc error `code` (message)".
pub(super) fn describe(function: &str, code: c_int) -> String {
    let mut text: *const std::ffi::c_char = std::ptr::null();
    let ok = unsafe { PetscErrorMessage(code, &mut text, std::ptr::null_mut()) } == 0 && !text.is_null();
    let message = if ok { unsafe { CStr::from_ptr(text) }.to_string_lossy().into_owned() } else { "unknown error".into() };
    format!("PETSc {function} failed with error {code}: {message}")
}

/// PETSc's name of a `KSPConvergedReason` of a failed solve.
pub(super) fn converged_reason(reason: c_int) -> &'static str {
    match reason {
        -3 => "KSP_DIVERGED_ITS: the iteration budget",
        -4 => "KSP_DIVERGED_DTOL: the residual grew",
        -5 => "KSP_DIVERGED_BREAKDOWN",
        -6 => "KSP_DIVERGED_BREAKDOWN_BICG",
        -7 => "KSP_DIVERGED_NONSYMMETRIC",
        -8 => "KSP_DIVERGED_INDEFINITE_PC",
        -9 => "KSP_DIVERGED_NANORINF",
        -10 => "KSP_DIVERGED_INDEFINITE_MAT",
        -11 => "KSP_DIVERGED_PC_FAILED",
        _ => "diverged",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The header constants the backend relies on, as `shim.c` read them from the
    /// installed PETSc: fails when a PETSc whose values moved is linked against a
    /// stale build, and says which.
    #[test]
    fn header_constants_are_those_of_petsc_3_18_or_later() {
        let v = super::super::version();
        assert!(v[0] == 3 && v[1] >= 18, "PETSc {v:?}");
        unsafe {
            assert_eq!(sc_sizeof_petsc_int, 4);
            assert_eq!(sc_sizeof_petsc_scalar, 8);
            assert_eq!((sc_PETSC_FALSE, sc_PETSC_TRUE), (0, 1));
            assert!(sc_PC_RIGHT >= 0 && sc_INSERT_VALUES >= 0);
        }
        initialize().unwrap();
        let (rank, size) = rank_and_size();
        assert!(rank < size);
    }
}
