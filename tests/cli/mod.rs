mod bad_input;
mod check;
mod import_export;
mod output_paths;
mod pipeline;
mod plot;
mod solve;
mod tag;
