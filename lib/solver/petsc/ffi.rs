//! Declarations of the PETSc C API this backend calls (PETSc ≥ 3.18, real double,
//! 32-bit `PetscInt`; `shim.c` stops the build on any other).
//!
//! The functions are PETSc's own, bound directly. The enum values come from the
//! installed headers through `shim.c` (`sc_*` statics), never from a table typed
//! here, so a PETSc whose enums moved still gets the right ones.

#![allow(non_upper_case_globals, non_camel_case_types)]

use std::ffi::{c_char, c_int, c_void};

pub type PetscErrorCode = c_int;
pub type PetscInt = i32;
pub type PetscReal = f64;
pub type PetscScalar = f64;
pub type PetscBool = c_int;

/// Opaque handles (pointers to PETSc's structs).
#[repr(transparent)]
#[derive(Clone, Copy, Debug)]
pub struct Handle(pub *mut c_void);

impl Handle {
    pub const NULL: Handle = Handle(std::ptr::null_mut());
    pub fn is_null(self) -> bool {
        self.0.is_null()
    }
}

pub type Mat = Handle;
pub type Vec_ = Handle;
pub type Ksp = Handle;
pub type Pc = Handle;
pub type MatNullSpace = Handle;
pub type VecScatter = Handle;

extern "C" {
    // shim.c: header constants and communicator-bound calls
    pub static sc_petsc_version: [c_int; 3];
    pub static sc_sizeof_petsc_int: c_int;
    pub static sc_sizeof_petsc_scalar: c_int;
    pub static sc_INSERT_VALUES: c_int;
    pub static sc_MAT_FINAL_ASSEMBLY: c_int;
    pub static sc_MAT_SYMMETRIC: c_int;
    pub static sc_MAT_NEW_NONZERO_ALLOCATION_ERR: c_int;
    pub static sc_PC_RIGHT: c_int;
    pub static sc_KSP_NORM_UNPRECONDITIONED: c_int;
    pub static sc_SCATTER_FORWARD: c_int;
    pub static sc_PETSC_TRUE: c_int;
    pub static sc_PETSC_FALSE: c_int;
    pub static sc_PETSC_DEFAULT: c_int;

    pub fn sc_initialize() -> PetscErrorCode;
    pub fn sc_comm_rank() -> c_int;
    pub fn sc_comm_size() -> c_int;
    pub fn sc_mat_create(a: *mut Mat) -> PetscErrorCode;
    pub fn sc_ksp_create(k: *mut Ksp) -> PetscErrorCode;
    pub fn sc_allreduce_sum_f64(x: *mut f64, n: c_int) -> c_int;
    pub fn sc_allreduce_max_f64(x: *mut f64, n: c_int) -> c_int;

    // PETSc
    pub fn PetscFinalize() -> PetscErrorCode;
    pub fn PetscErrorMessage(code: c_int, text: *mut *const c_char, specific: *mut *mut c_char) -> PetscErrorCode;
    pub fn PetscOptionsInsertString(options: *mut c_void, s: *const c_char) -> PetscErrorCode;

    pub fn MatSetSizes(a: Mat, m: PetscInt, n: PetscInt, mg: PetscInt, ng: PetscInt) -> PetscErrorCode;
    pub fn MatSetBlockSize(a: Mat, bs: PetscInt) -> PetscErrorCode;
    pub fn MatSetType(a: Mat, t: *const c_char) -> PetscErrorCode;
    pub fn MatXAIJSetPreallocation(
        a: Mat,
        bs: PetscInt,
        dnnz: *const PetscInt,
        onnz: *const PetscInt,
        dnnzu: *const PetscInt,
        onnzu: *const PetscInt,
    ) -> PetscErrorCode;
    pub fn MatSetOption(a: Mat, op: c_int, flg: PetscBool) -> PetscErrorCode;
    pub fn MatSetValuesBlocked(
        a: Mat,
        m: PetscInt,
        idxm: *const PetscInt,
        n: PetscInt,
        idxn: *const PetscInt,
        v: *const PetscScalar,
        mode: c_int,
    ) -> PetscErrorCode;
    pub fn MatAssemblyBegin(a: Mat, t: c_int) -> PetscErrorCode;
    pub fn MatAssemblyEnd(a: Mat, t: c_int) -> PetscErrorCode;
    pub fn MatCreateVecs(a: Mat, right: *mut Vec_, left: *mut Vec_) -> PetscErrorCode;
    pub fn MatNullSpaceCreateRigidBody(coords: Vec_, sp: *mut MatNullSpace) -> PetscErrorCode;
    pub fn MatSetNearNullSpace(a: Mat, sp: MatNullSpace) -> PetscErrorCode;
    pub fn MatNullSpaceDestroy(sp: *mut MatNullSpace) -> PetscErrorCode;
    pub fn MatDestroy(a: *mut Mat) -> PetscErrorCode;

    pub fn VecGetArray(v: Vec_, a: *mut *mut PetscScalar) -> PetscErrorCode;
    pub fn VecRestoreArray(v: Vec_, a: *mut *mut PetscScalar) -> PetscErrorCode;
    pub fn VecGetArrayRead(v: Vec_, a: *mut *const PetscScalar) -> PetscErrorCode;
    pub fn VecRestoreArrayRead(v: Vec_, a: *mut *const PetscScalar) -> PetscErrorCode;
    pub fn VecDuplicate(v: Vec_, w: *mut Vec_) -> PetscErrorCode;
    pub fn VecDestroy(v: *mut Vec_) -> PetscErrorCode;
    pub fn VecScatterCreateToAll(v: Vec_, ctx: *mut VecScatter, all: *mut Vec_) -> PetscErrorCode;
    pub fn VecScatterBegin(ctx: VecScatter, x: Vec_, y: Vec_, mode: c_int, smode: c_int) -> PetscErrorCode;
    pub fn VecScatterEnd(ctx: VecScatter, x: Vec_, y: Vec_, mode: c_int, smode: c_int) -> PetscErrorCode;
    pub fn VecScatterDestroy(ctx: *mut VecScatter) -> PetscErrorCode;

    pub fn KSPSetOperators(k: Ksp, a: Mat, p: Mat) -> PetscErrorCode;
    pub fn KSPSetType(k: Ksp, t: *const c_char) -> PetscErrorCode;
    pub fn KSPGetPC(k: Ksp, pc: *mut Pc) -> PetscErrorCode;
    pub fn KSPSetOptionsPrefix(k: Ksp, prefix: *const c_char) -> PetscErrorCode;
    pub fn KSPSetTolerances(k: Ksp, rtol: PetscReal, abstol: PetscReal, dtol: PetscReal, maxits: PetscInt) -> PetscErrorCode;
    pub fn KSPSetNormType(k: Ksp, t: c_int) -> PetscErrorCode;
    pub fn KSPSetPCSide(k: Ksp, side: c_int) -> PetscErrorCode;
    pub fn KSPGMRESSetRestart(k: Ksp, restart: PetscInt) -> PetscErrorCode;
    pub fn KSPSetReusePreconditioner(k: Ksp, flg: PetscBool) -> PetscErrorCode;
    pub fn KSPSetFromOptions(k: Ksp) -> PetscErrorCode;
    pub fn KSPSetUp(k: Ksp) -> PetscErrorCode;
    pub fn KSPSolve(k: Ksp, b: Vec_, x: Vec_) -> PetscErrorCode;
    pub fn KSPGetIterationNumber(k: Ksp, its: *mut PetscInt) -> PetscErrorCode;
    pub fn KSPGetConvergedReason(k: Ksp, reason: *mut c_int) -> PetscErrorCode;
    pub fn KSPDestroy(k: *mut Ksp) -> PetscErrorCode;
    pub fn PCSetType(pc: Pc, t: *const c_char) -> PetscErrorCode;
    pub fn PCFactorSetMatSolverType(pc: Pc, t: *const c_char) -> PetscErrorCode;
}
