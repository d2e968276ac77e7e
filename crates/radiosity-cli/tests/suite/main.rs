//! The `radiosity` program's integration tests, one binary (`cargo test -p radiosity-cli
//! --test suite`): one module per topic.

mod commands;
mod view;
