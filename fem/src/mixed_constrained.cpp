#include "mixed_constrained.hpp"

#include <vector>

namespace spinesim::fem {

MixedConstrained assemble_mixed_constrained(const FeSpace& p2, const Eigen::MatrixX4i& T,
                                            const Eigen::VectorXi& region,
                                            const mesh::RegionMaterials& materials,
                                            const std::vector<NodeRole>& roles,
                                            const FreeBlockPattern& numbering,
                                            const Eigen::Vector3d& c, const ElementFibres* fibres) {
  MixedConstrained out;
  out.pressure = make_pressure_space(T, region);
  const Eigen::Index nu = 3 * numbering.num_free_nodes, n = nu + out.pressure.size();
  out.coupling.K_fp.setZero(n, 6);
  out.coupling.K_pp.setZero();
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(std::size_t(p2.elements.rows()) * (465 + 120 + 10));
  MixedElement e;
  TetVertices X;
  int node[10], A[10];
  bool plate[10];
  Eigen::Matrix<double, 3, 6> R[10];
  for (Eigen::Index t = 0; t < p2.elements.rows(); ++t) {
    const mesh::IsotropicMaterial& m = materials.at(region(t));
    for (int a = 0; a < 4; ++a) X.row(a) = p2.X.row(p2.elements(t, a));
    element_mixed(X, m.shear_modulus_mpa(), bulk_modulus_mpa(m), e);
    if (fibres != nullptr) add_element_fibres(*fibres, t, X, e.A);
    for (int a = 0; a < 10; ++a) {
      node[a] = p2.elements(t, a);
      A[a] = numbering.free_index[std::size_t(node[a])];
      plate[a] = roles[std::size_t(node[a])] == NodeRole::plate;
      if (plate[a]) R[a] = plate_map(p2.X.row(node[a]).transpose() - c);
    }
    // Displacement–displacement blocks.
    for (int a = 0; a < 10; ++a)
      for (int b = 0; b < 10; ++b) {
        const auto Kab = e.A.block<3, 3>(3 * a, 3 * b);
        if (A[a] >= 0 && A[b] >= 0) {
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
              if (3 * A[a] + i >= 3 * A[b] + j)
                trip.emplace_back(3 * A[a] + i, 3 * A[b] + j, Kab(i, j));
        } else if (A[a] >= 0 && plate[b]) {
          out.coupling.K_fp.block<3, 6>(3 * A[a], 0).noalias() += Kab * R[b];
        } else if (plate[a] && plate[b]) {
          out.coupling.K_pp.noalias() += R[a].transpose() * Kab * R[b];
        }
      }
    // Pressure rows: B against displacements, -C among pressures.
    for (int i = 0; i < 4; ++i) {
      const Eigen::Index pi = nu + out.pressure.elements(t, i);
      for (int b = 0; b < 10; ++b) {
        const auto Bib = e.B.block<1, 3>(i, 3 * b);
        if (A[b] >= 0) {
          for (int j = 0; j < 3; ++j) trip.emplace_back(pi, 3 * A[b] + j, Bib(j));
        } else if (plate[b]) {
          out.coupling.K_fp.row(pi).noalias() += Bib * R[b];
        }
      }
      for (int j = 0; j < 4; ++j) {
        const Eigen::Index pj = nu + out.pressure.elements(t, j);
        if (pi >= pj) trip.emplace_back(pi, pj, -e.C(i, j));
      }
    }
  }
  out.lower.resize(n, n);
  out.lower.setFromTriplets(trip.begin(), trip.end());
  return out;
}

}  // namespace spinesim::fem
