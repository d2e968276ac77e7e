//! The library's integration tests, one binary (`cargo test -p radiosity --test suite`):
//! one module per topic, the scenes and helpers they share in `fixtures`.

mod fixtures;

mod adaptive;
mod compare;
mod exposure;
mod form_factors;
mod hierarchical;
mod methods_on_examples;
mod progressive;
mod scale_invariance;
