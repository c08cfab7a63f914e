mod bad_input;
mod import_export;
mod pipeline;
mod solve;
mod tag;
