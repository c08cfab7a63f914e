mod bad_input;
mod check;
mod import_export;
mod pipeline;
mod plot;
mod solve;
mod tag;
