/* The C side of splinecontact's PETSc backend (lib/solver/petsc/ffi.rs).
 *
 * PETSc's functions are bound directly from Rust (`extern "C"`); this file only
 * carries what Rust cannot read from a shared library:
 *   - the values of PETSc's enums and macros, taken from the installed headers at
 *     build time (they change between versions: ADD_VALUES, MAT_SPD, ...);
 *   - the calls that take an MPI_Comm (PETSC_COMM_WORLD is a pointer under Open
 *     MPI and an int under MPICH, so it never crosses into Rust);
 *   - the few MPI reductions the program needs for its own messages.
 * The #error lines stop the build on a PETSc that the Rust declarations would
 * misread. */
#include <petscksp.h>

#if PETSC_VERSION_LT(3, 18, 0)
#error "splinecontact's petsc feature needs PETSc 3.18 or later"
#endif
#if defined(PETSC_USE_64BIT_INDICES)
#error "splinecontact's petsc feature is declared for 32-bit PetscInt: use a PETSc configured without --with-64-bit-indices (Debian's libpetsc-real-dev is)"
#endif
#if defined(PETSC_USE_COMPLEX) || !defined(PETSC_USE_REAL_DOUBLE)
#error "splinecontact's petsc feature needs a real, double-precision PETSc (Debian: libpetsc-real-dev)"
#endif

const int sc_petsc_version[3] = {PETSC_VERSION_MAJOR, PETSC_VERSION_MINOR, PETSC_VERSION_SUBMINOR};
const int sc_sizeof_petsc_int = (int)sizeof(PetscInt);
const int sc_sizeof_petsc_scalar = (int)sizeof(PetscScalar);

const int sc_INSERT_VALUES = INSERT_VALUES;
const int sc_MAT_FINAL_ASSEMBLY = MAT_FINAL_ASSEMBLY;
const int sc_MAT_SYMMETRIC = MAT_SYMMETRIC;
const int sc_MAT_NEW_NONZERO_ALLOCATION_ERR = MAT_NEW_NONZERO_ALLOCATION_ERR;
const int sc_PC_RIGHT = PC_RIGHT;
const int sc_KSP_NORM_UNPRECONDITIONED = KSP_NORM_UNPRECONDITIONED;
const int sc_SCATTER_FORWARD = SCATTER_FORWARD;
const int sc_PETSC_TRUE = PETSC_TRUE;
const int sc_PETSC_FALSE = PETSC_FALSE;
const int sc_PETSC_DEFAULT = PETSC_DEFAULT;

/* Starts PETSc (and MPI, when the program did not). PETSc's own signal handler
 * stays off (Rust reports its panics itself) and errors return to the caller
 * instead of printing a traceback: the Rust side names the failed function. */
PetscErrorCode sc_initialize(void)
{
  PetscErrorCode ierr;
  PetscBool done;
  ierr = PetscInitialized(&done);
  if (ierr || done) return ierr;
  ierr = PetscOptionsSetValue(NULL, "-no_signal_handler", NULL);
  if (ierr) return ierr;
  ierr = PetscOptionsSetValue(NULL, "-options_left", "no");
  if (ierr) return ierr;
  ierr = PetscInitializeNoArguments();
  if (ierr) return ierr;
  ierr = PetscPushErrorHandler(PetscReturnErrorHandler, NULL);
  return ierr;
}

int sc_comm_rank(void)
{
  int r = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &r);
  return r;
}

int sc_comm_size(void)
{
  int s = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &s);
  return s;
}

PetscErrorCode sc_mat_create(Mat *a) { return MatCreate(PETSC_COMM_WORLD, a); }
PetscErrorCode sc_ksp_create(KSP *k) { return KSPCreate(PETSC_COMM_WORLD, k); }

/* In-place sums and maxima over all ranks (the program's own messages). */
int sc_allreduce_sum_f64(double *x, int n)
{
  return MPI_Allreduce(MPI_IN_PLACE, x, n, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
}

int sc_allreduce_max_f64(double *x, int n)
{
  return MPI_Allreduce(MPI_IN_PLACE, x, n, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
}
