mod bad_input;
mod check;
mod import_export;
mod paraview;
mod pipeline;
mod plot;
mod solve;
mod tag;
