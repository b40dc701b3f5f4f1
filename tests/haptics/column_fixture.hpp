// A stand-in spine for the compliant-stage tests: 17 "vertebrae" as 10 mm boxes 30 mm apart
// along y (T1 on top), body i = vertebra i; and the device states and render outputs the stage's
// tests feed it.
#pragma once

#include "spinesim/haptics/compliant_stage.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace spinesim::haptics::testing {

/// A closed box of half-size h centred at c (12 triangles, outward normals).
inline mesh::TriSurface box(const Eigen::Vector3d& c, double h) {
  mesh::TriSurface s;
  s.V.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    s.V.row(i) =
        (c + h * Eigen::Vector3d(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1)).transpose();
  s.F.resize(12, 3);
  s.F << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6,
      1, 3, 5, 3, 7, 5;
  return s;
}

struct Column {
  Scene scene;
  std::vector<Eigen::Vector3d> centres;
  std::array<int, kSpineVertebrae> body_of{};
  Column() {
    for (int i = 0; i < kSpineVertebrae; ++i) {
      centres.push_back(Eigen::Vector3d(0, 600 - 30.0 * i, 0));
      scene.add_body("V" + std::to_string(i), box(centres.back(), 5));
      body_of[std::size_t(i)] = i;
    }
  }
};

/// The device at `p` with `buttons` held, turned by R.
inline DeviceState at(const Eigen::Vector3d& p, unsigned buttons,
                      const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  DeviceState s;
  s.position_mm = p;
  s.buttons = buttons;
  s.orientation = R;
  return s;
}

/// A render that touched `body` with the proxy at `proxy`.
inline RenderOutput touching(int body, const Eigen::Vector3d& proxy) {
  RenderOutput r;
  r.contact = true;
  r.body = body;
  r.proxy_mm = proxy;
  return r;
}

}  // namespace spinesim::haptics::testing
