/// @file
/// The Standard Input Data (SID) of a flexible body (Wallrapp1994; SchwertassekWallrapp1999,
/// ch. 6): the reduced
/// body as Taylor objects in its elastic coordinates q, and its conversion to and from
/// flexmbd's spatial invariants (FfrInvariants3d). The text file is fe_import/sid_file.hpp; the
/// blocks, their conventions and what is checked: docs/fe-import.md, "SID".
#pragma once

#include <string>
#include <vector>

#include "bodies/ffr_invariants_3d.hpp"

namespace flexmbd {

/// A Taylor object: the matrix function A(q) = M0 + sum_k M1_k q_k (order 1)
/// + sum_kl M2_kl q_k q_l (order 2) of the nq elastic coordinates (Wallrapp1994).
struct SidTaylor {
  /// How M0 is stored in the file: 0 zero (no entries), 1 diagonal, 2 symmetric (the
  /// lower triangle i >= j), 3 full. M1 and M2 entries are stored as they are.
  enum Structure { Zero = 0, Diagonal = 1, Symmetric = 2, Full = 3 };
  std::string name;  ///< the block's name in the file ("mdCM", "J", "origin", ...)
  int order = 0;     ///< 0, 1 or 2
  int nrow = 0, ncol = 0;
  int nq = 0;   ///< elastic coordinates M1 depends on (order >= 1), else 0
  int nqn = 0;  ///< elastic coordinates of M2 (order 2), else 0
  int structure = Full;
  MatX m0;                ///< nrow x ncol
  std::vector<MatX> m1;   ///< order >= 1: nq matrices nrow x ncol (M1_k)
  std::vector<MatX> m2;   ///< order 2: nqn^2 matrices, M2_kl at k + nqn l

  /// A zero object of the given shape (m1 / m2 sized by the order).
  static SidTaylor zero(std::string name, int order, int nrow, int ncol, int nq, int structure);
};

/// One node of the SID's frame: where joints and forces attach.
struct SidNode {
  std::string name;    ///< "new node = <name>"
  std::string rframe;  ///< the frame the node is given in ("body ref")
  SidTaylor origin;    ///< 3 x 1, order 1: u0 + N q (M1_k = column k of phi)
  SidTaylor phi;       ///< 3 x nq, order 0: the translational shapes N
  SidTaylor psi;       ///< 3 x nq, order 0: the rotational shapes N_theta
  SidTaylor ap;        ///< "AP" 3 x 3, order 1: the node frame I + skew(N_theta q)
};

/// A whole SID (blocks named as in the file; their definitions: Wallrapp1994).
struct SidData {
  double mass = 0.0;                   ///< refmod: m
  std::vector<std::string> modeNames;  ///< refmod: ielastq(1..nq)
  std::vector<SidNode> nodes;          ///< frame
  SidTaylor mdCM;    ///< 3 x 1: int rho u dV (m times the centre of mass)
  SidTaylor J;       ///< 3 x 3: the inertia tensor about the frame origin, int rho u~^T u~ dV
  SidTaylor Ct;      ///< nq x 3: S-bar^T, the coupling with translation
  SidTaylor Cr;      ///< nq x 3: (int rho u~ N dV)^T, the coupling with rotation
  SidTaylor Me;      ///< nq x nq: m_ff
  SidTaylor Gr;      ///< 3 x 3 nq: block j = -2 int rho u~ N_j~ dV (gyroscopic, rotation rows; Wallrapp1994)
  SidTaylor Ge;      ///< nq x 3 nq: block j = 2 int rho N^T N_j~ dV (gyroscopic, elastic rows)
  SidTaylor Oe;      ///< nq x 6: centrifugal, columns w_x^2, w_y^2, w_z^2, w_x w_y, w_y w_z, w_x w_z;
                     ///< its first-order term holds the spin softening and stiffening
  SidTaylor ksigma;  ///< nq x 1: generalised forces of reference stresses (flexmbd: none)
  SidTaylor Ke;      ///< nq x nq: K_ff
  SidTaylor De;      ///< nq x nq: D_ff

  int numElastic() const { return static_cast<int>(modeNames.size()); }
  /// The Taylor blocks of the body (not the nodes'), in file order.
  std::vector<const SidTaylor*> blocks() const;
  std::vector<SidTaylor*> blocks();
};

/// The SID of a spatial body's invariants: every block from m, the first and second
/// moments, the position shapes, S-bar, the S_kl, m_ff, K_ff, D_ff, and the section
/// rotation terms R_kl (J to second order) and H_i (in Cr's first-order term) and the spin
/// stiffness G_kl (in Oe's first-order term) where the invariants have them; nodes from
/// the points. `modeNames` (nf of them; empty: "q1", ...).
SidData sidFromInvariants(const FfrInvariants3d& inv, std::vector<std::string> modeNames = {});

/// The invariants of a SID. Read from mass, mdCM, J, Cr (zeroth and first order), Me, Gr
/// (first order: the S_kl), Ke, De, Oe's first-order terms beyond the inertia (the spin
/// stiffness G_kl) and the nodes; the other blocks (Ct, Ge, Oe's inertia part, the nodes'
/// origin M1 and AP) are redundant and must equal what those give, to kSidConsistency of
/// each Taylor term's largest entry, so a file written in other conventions is refused
/// rather than misread.
/// @throws InputError naming `owner`, the block and the entry: sizes that do not match
/// nelastq, a redundant block that differs (Ct's or a node's phi's first-order terms:
/// stiffening by translational acceleration or by nodal forces, not supported), reference
/// stresses (ksigma not zero), Gr without its first-order term (the S_kl), a spin
/// stiffness that is not symmetric, or invariants that fail their checks.
FfrInvariants3d invariantsFromSid(const SidData& sid, const std::string& owner);

/// The redundant blocks agree when they differ by at most this fraction of the Taylor
/// term's largest entry: 1e-8 admits files printed to 9 significant digits; flexmbd
/// prints 17, so a file it wrote differs by round-off.
constexpr double kSidConsistency = 1e-8;

}  // namespace flexmbd
