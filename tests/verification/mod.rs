mod solid;
mod contact;
mod parisch;
mod benchmarks;
mod friction;
mod paper_examples;
mod ironing;
mod shallow_ironing;
mod sliding;
mod tube;
mod mortar_atlas;
mod multipatch_seam;
mod ccx_compare;
mod crash;
mod determinism;
#[cfg(feature = "petsc")]
mod petsc;
