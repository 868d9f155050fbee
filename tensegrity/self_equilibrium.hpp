/// @file
/// Self-equilibrium of a tensegrity (Doc001, sec. 1; the force-density
/// method of Schek1974 and PellegrinoCalladine1986): with force densities q_j =
/// t_j / l_j (tension positive), the equilibrium of the free node coordinates reads
///   A q = f,   A[node i, member j] = x_i - x_k  (j joins i and k),
/// so self-stress states (f = 0) span the null space of the equilibrium matrix A,
/// computed with the SVD.
#pragma once

#include "tensegrity/tensegrity_structure.hpp"

namespace flexmbd {

struct SelfStressStates {
  /// Members in the order of TensegrityStructure::members() (struts, then cables);
  /// one column per independent self-stress state, unit norm.
  MatX forceDensities;
  VecX singularValues;  ///< of A, descending
  int rank = 0;         ///< of A
  /// Infinitesimal mechanisms (PellegrinoCalladine1986): free coordinates - rank (rigid
  /// body motions of an unsupported structure included).
  int mechanisms = 0;
};

/// Equilibrium matrix A (free coordinates x members) at full positions x.
MatX equilibriumMatrix(const TensegrityStructure& s, const VecX& x);

/// Null space of A: singular values below relativeTolerance * sigma_max count as zero.
/// @pre s finalized.
SelfStressStates computeSelfStress(const TensegrityStructure& s, const VecX& x, double relativeTolerance = 1e-10);

/// Prestresses s in its initial geometry with the self-stress q (one force density per
/// member, struts then cables) times `scale`: natural lengths are set so that the
/// member forces t_j = q_j l_j hold at the initial lengths,
///   elastic member  t = EA (l - l0)/l0 (Doc001)  =>  l0 = l / (1 + t/EA),
///   inextensible cable: l0 = l (its tension is carried by the LCP).
/// @throws InputError if a cable would be compressed (q_j scale < 0) or a strut
/// stretched, naming the member.
void applyPrestress(TensegrityStructure& s, const VecX& forceDensities, double scale);

}  // namespace flexmbd
