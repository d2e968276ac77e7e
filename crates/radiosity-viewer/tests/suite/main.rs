//! The viewer's integration tests, one binary (`cargo test -p radiosity-viewer --test
//! suite`): one module per topic.

mod offscreen;
