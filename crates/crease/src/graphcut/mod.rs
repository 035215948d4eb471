//! Exact minimisation of binary energies by one minimum s-t cut.
//!
//! * [`maxflow`]: the Boykov–Kolmogorov max-flow / min-cut algorithm ([`Graph`]).
//! * [`mod@potts`]: binary energies with submodular pairwise terms (Kolmogorov & Zabih, "What
//!   energy functions can be minimized via graph cuts?", PAMI 2004), among them the
//!   Potts / Ising model Σ D_i(x_i) + λ Σ w_ij [x_i ≠ x_j] of vidal et al. 2011 (equation 1),
//!   over an edge list or a CSR neighbour graph.

pub mod maxflow;
pub mod potts;

pub use maxflow::Graph;
pub use potts::{potts, potts_csr, undirected_edges, BinaryEnergy, Labelling};
