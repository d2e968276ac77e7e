//! The `radiosity` program's integration tests, one binary (`cargo test -p radiosity-cli
//! --test suite`): one module per topic, what they share in `fixtures`.

mod fixtures;

mod browser;
mod commands;
mod first_hour;
mod formats_out;
mod hostile;
mod illuminance;
mod imports;
mod pathtrace;
mod validate;
mod view;
