// Force rendering of the rigid stage: what the probe (a sphere at the device's position) feels
// from the scene. Two renderers behind one interface:
//   - SphereProxyRenderer (default): a god-object / proxy (Zilles & Salisbury 1995; Ruspini,
//     Kolarov & Khatib 1997) — a sphere of the probe's radius that follows the device but never
//     enters a surface; the force is a spring from the device to it. Thin features cannot be
//     pushed through.
//   - GaoGibsonRenderer: the thesis's probe-normal penalty method (Gao & Gibson 2006; thesis
//     4.4.2, eqs 4.9-4.11), with the thesis's units fixed (see its comment).
// A render call allocates nothing and reads the scene and poses it is given.
#pragma once

#include "spinesim/haptics/scene.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace spinesim::haptics {

struct ProbeState {
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();    ///< world frame
  Eigen::Vector3d velocity_mm_s = Eigen::Vector3d::Zero();  ///< world frame
};

struct RenderOutput {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();  ///< on the probe (the user's hand), world
  bool contact = false;
  int body = -1;                                       ///< touched body (−1: none)
  double penetration_mm = 0;                           ///< device behind the surface (proxy) or
                                                       ///< deepest sample (Gao–Gibson)
  Eigen::Vector3d proxy_mm = Eigen::Vector3d::Zero();  ///< the proxy (Gao–Gibson: the probe)
  int candidates = 0;                                  ///< triangles looked at this tick
  int work = 0;  ///< collision work: tree nodes visited + triangles swept (proxy), or candidates
  bool truncated = false;  ///< the tick's work reached its bound (or a fixed buffer was full)
  /// Disc palpation (disc_palpation.hpp): the disc's state this render used.
  bool disc = false;
  bool disc_contact = false;
  double disc_volume_change = 0;                            ///< (V - V0) / V0
  Eigen::Vector3d disc_force_n = Eigen::Vector3d::Zero();   ///< the disc's force on its probe
  double disc_indentation_mm = 0;  ///< the disc wall's indentation under the probe (mm)
  Eigen::Vector3d disc_probe_mm = Eigen::Vector3d::Zero();  ///< the simulated probe
};

class ForceRenderer {
 public:
  virtual ~ForceRenderer() = default;
  virtual const char* name() const = 0;
  /// Starts again with the device at `device_mm` (the proxy jumps there, no memory of contact).
  virtual void reset(const Eigen::Vector3d& device_mm) = 0;
  virtual RenderOutput render(const ProbeState& probe, const Scene& scene, const ScenePoses& poses,
                              double dt_s) = 0;
};

struct ProxyParameters {
  double radius_mm = 5.0;
  double stiffness_n_per_mm = 0.5;  ///< spring from the device to the proxy
  double damping_n_s_per_mm = 0.0;  ///< on the device's velocity, in contact only
  double skin_mm = 1e-3;            ///< the proxy stops this far from a surface
  /// The tick's bound on collision work: tree nodes visited plus triangles swept, over every
  /// body and proxy iteration. At the bound the proxy stops where the search has proven the
  /// way free and goes on next tick (RenderOutput::truncated).
  int max_work = 4096;
};

class SphereProxyRenderer final : public ForceRenderer {
 public:
  explicit SphereProxyRenderer(const ProxyParameters& p);
  const char* name() const override { return "proxy"; }
  void reset(const Eigen::Vector3d& device_mm) override;
  RenderOutput render(const ProbeState& probe, const Scene& scene, const ScenePoses& poses,
                      double dt_s) override;
  /// The proxy in world coordinates under `poses` (it rides the body it last touched).
  Eigen::Vector3d proxy_world(const ScenePoses& poses) const;

 private:
  ProxyParameters p_;
  Eigen::Vector3d proxy_ = Eigen::Vector3d::Zero();  ///< world, or in `anchor_`'s frame
  int anchor_ = -1;                                  ///< body the proxy rides (−1: world)
};

/// Which magnitude law of the thesis: eq 4.9 (sum over the samples) or eq 4.10 (the same sum
/// divided by the probe's largest cross-section πr²).
enum class GaoGibsonLaw { eq_4_9, eq_4_10 };

struct GaoGibsonParameters {
  double radius_mm = 5.0;
  GaoGibsonLaw law = GaoGibsonLaw::eq_4_10;
  /// Units (the thesis leaves them inconsistent: its k multiplies a count of points, so the
  /// force depends on how densely the surface is sampled). Here each sample stands for its
  /// area a_i, and the sum is Σ (k s_i + d ṡ_i) a_i — an integral over the surface inside the
  /// probe, independent of the sampling. Eq 4.9: k in N/mm³ (N per mm of depth per mm² of
  /// surface), d in N·s/mm³. Eq 4.10 divides by πr² (mm²): k in N/mm, d in N·s/mm — the force is
  /// k times the mean depth over the probe's cross-section.
  double stiffness = 0.5;
  double damping = 0.0;
  double sample_spacing_mm = 0.25;  ///< the scene must be sampled at this spacing
  int max_triangles = 8192;         ///< fixed candidate buffer
};

class GaoGibsonRenderer final : public ForceRenderer {
 public:
  explicit GaoGibsonRenderer(const GaoGibsonParameters& p);
  const char* name() const override { return "gao-gibson"; }
  void reset(const Eigen::Vector3d&) override {}
  RenderOutput render(const ProbeState& probe, const Scene& scene, const ScenePoses& poses,
                      double dt_s) override;

 private:
  GaoGibsonParameters p_;
  std::vector<int> candidates_;  ///< sized once, in the constructor
};

}  // namespace spinesim::haptics
