mod solid;
mod contact;
mod parisch;
mod benchmarks;
mod friction;
