//! `radiosity-mpi`: the form-factor matrix computed across the ranks of an MPI job, written
//! byte for byte as `radiosity formfactors` writes it.
//!
//! This library holds what needs no MPI, so that it is built and tested everywhere: the
//! dealing of row blocks ([`deal`]), the checkpoint directory ([`checkpoint`]) and the
//! messages between the ranks ([`wire`]). The program (src/main.rs, default feature `mpi`) runs the
//! ranks over them.

pub mod checkpoint;
pub mod deal;
pub mod wire;
