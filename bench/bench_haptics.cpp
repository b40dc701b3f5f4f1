// Collision queries and render ticks of the rigid stage.
//   SphereQuery/<impl>/<radius mm>: all triangles of a parametric L3 (8000 triangles) within a
//     sphere at random probes near the surface; impl 0 = the thesis's tree (haptics::AabbTree),
//     1 = CGAL 5.5 AABB_tree::all_intersected_primitives(Sphere_3) (which finds the triangles
//     crossing the sphere's surface: a subset), 2 = CGAL's box query around the ball followed by
//     the exact ball-triangle test (the same set as ours).
//   ProxyTick/<radius mm>, GaoGibsonTick/<radius mm>: one render() on the 18-body spine
//     (parametric, 6000 triangles each) along the shipped spinous-process stroke.
//   DiscPalpationStep/<cell size, 0.1 mm>/<pressed>: one disc-thread step (haptics/
//     disc_palpation.hpp) of the L4-L5 CGAL disc with the tuned model's terms (main, radial,
//     torsion springs and the per-tet volume term; the scales do not change the cost), the 4 mm
//     probe free (0) or held 2 mm into the anterior wall (1); frozen implicit Euler at 1 ms.
//     A third argument 1 adds the embedded fibre elements of a fibre-reinforced annulus (the
//     network `calibrate --nonlinear` fits): their frozen steps are line-searched.
#include "spinesim/haptics/device.hpp"
#include "spinesim/haptics/disc_palpation.hpp"
#include "spinesim/haptics/hostile.hpp"
#include "spinesim/haptics/renderer.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/vertebra_geometry.hpp"
#include "spinesim/mss/boundary.hpp"

#include <benchmark/benchmark.h>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <vector>

namespace sh = spinesim::haptics;
namespace sm = spinesim::mesh;

namespace {

using K = CGAL::Simple_cartesian<double>;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_triangle_primitive<K, Iterator>>>;

const sm::TriSurface& l3() {
  static const sm::TriSurface s =
      sm::mesh_vertebra(sm::parametric_vertebra("L3", SPINESIM_DATA_DIR), 8000).surface;
  return s;
}

// Probe centres within 5 mm of the surface (vertex + random offset), fixed seed.
std::vector<Eigen::Vector3d> probes(const sm::TriSurface& s, int n) {
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> pick(0, int(s.V.rows()) - 1);
  std::normal_distribution<double> off(0, 3);
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i)
    p.push_back(s.V.row(pick(rng)).transpose() + Eigen::Vector3d(off(rng), off(rng), off(rng)));
  return p;
}

void SphereQuery(benchmark::State& state) {
  const auto& s = l3();
  const double r = double(state.range(1));
  const auto p = probes(s, 4096);
  std::size_t i = 0, found = 0;
  if (state.range(0) == 0) {
    const sh::AabbTree tree(s.V, s.F);
    std::vector<int> buffer(20000);
    for (auto _ : state) {
      found +=
          std::size_t(tree.sphere_query(p[i++ % p.size()], r, buffer.data(), int(buffer.size())));
      benchmark::ClobberMemory();
    }
  } else {
    std::vector<Triangle> triangles;
    for (Eigen::Index t = 0; t < s.F.rows(); ++t) {
      auto P = [&](int k) {
        const Eigen::Vector3d x = s.V.row(s.F(t, k));
        return K::Point_3(x.x(), x.y(), x.z());
      };
      triangles.emplace_back(P(0), P(1), P(2));
    }
    CgalTree tree(triangles.begin(), triangles.end());
    tree.accelerate_distance_queries();
    std::vector<Iterator> hits;
    hits.reserve(20000);
    const bool ball = state.range(0) == 2;
    for (auto _ : state) {
      hits.clear();
      const Eigen::Vector3d& c = p[i++ % p.size()];
      if (!ball) {
        tree.all_intersected_primitives(K::Sphere_3(K::Point_3(c.x(), c.y(), c.z()), r * r),
                                        std::back_inserter(hits));
        found += hits.size();
      } else {
        // The same set as ours: the box around the ball, then the exact ball-triangle test.
        tree.all_intersected_primitives(
            CGAL::Bbox_3(c.x() - r, c.y() - r, c.z() - r, c.x() + r, c.y() + r, c.z() + r),
            std::back_inserter(hits));
        for (const auto& it : hits) {
          const Eigen::Vector3d a(it->vertex(0).x(), it->vertex(0).y(), it->vertex(0).z()),
              b(it->vertex(1).x(), it->vertex(1).y(), it->vertex(1).z()),
              d(it->vertex(2).x(), it->vertex(2).y(), it->vertex(2).z());
          found += (sh::closest_point_on_triangle(c, a, b, d) - c).squaredNorm() <= r * r;
        }
      }
    }
  }
  state.counters["triangles_per_query"] = double(found) / double(state.iterations());
  state.SetLabel(state.range(0) == 0   ? "thesis AABB tree, ball"
                 : state.range(0) == 1 ? "CGAL AABB_tree, Sphere_3 (surface only)"
                                       : "CGAL AABB_tree, box + ball test");
}
BENCHMARK(SphereQuery)->ArgsProduct({{0, 1, 2}, {2, 5, 10}})->Unit(benchmark::kMicrosecond);

struct SpineScene {
  sh::Scene scene;
  sh::Trajectory stroke;
  SpineScene() {
    for (const auto& name : sm::scene_body_names())
      scene.add_body(
          name, sm::mesh_vertebra(sm::parametric_vertebra(name, SPINESIM_DATA_DIR), 6000).surface);
    stroke = sh::read_trajectory(std::string(SPINESIM_DATA_DIR) + "/haptics/stroke_spinous.csv");
  }
};
SpineScene& spine() {
  static SpineScene s;
  return s;
}

template <class Renderer, class Params>
void tick(benchmark::State& state, Params p) {
  auto& s = spine();
  Renderer renderer(p);
  const sh::ScenePoses poses{};
  const double T = 1e-3;
  double t = 0;
  renderer.reset(s.stroke.position_at(0));
  std::size_t contacts = 0;
  for (auto _ : state) {
    sh::ProbeState probe{s.stroke.position_at(t), s.stroke.velocity_at(t)};
    const auto out = renderer.render(probe, s.scene, poses, T);
    contacts += out.contact;
    benchmark::DoNotOptimize(out);
    t += T;
    if (t > s.stroke.duration_s()) t = 0;
  }
  state.counters["contact_fraction"] = double(contacts) / double(state.iterations());
}

void ProxyTick(benchmark::State& state) {
  sh::ProxyParameters p;
  p.radius_mm = double(state.range(0));
  tick<sh::SphereProxyRenderer>(state, p);
}
BENCHMARK(ProxyTick)->Arg(2)->Arg(4)->Arg(10)->Unit(benchmark::kMicrosecond);

void GaoGibsonTick(benchmark::State& state) {
  auto& s = spine();
  if (s.scene.body(0).samples.first.empty()) s.scene.sample_surfaces(0.25);
  sh::GaoGibsonParameters p;
  p.radius_mm = double(state.range(0));
  tick<sh::GaoGibsonRenderer>(state, p);
}
BENCHMARK(GaoGibsonTick)->Arg(2)->Arg(4)->Arg(10)->Unit(benchmark::kMicrosecond);

// The proxy along each hostile trajectory (haptics/hostile.hpp; the device at the set-point,
// no hand): the mean per tick from the benchmark, the tail and the largest collision work from
// the ticks' own clocks. Arg: the trajectory (0 teleport … 5 hammer), the work bound.
void HostileProxyTick(benchmark::State& state) {
  auto& s = spine();
  const std::string name = sh::hostile_names()[std::size_t(state.range(0))];
  const sh::Trajectory path = sh::hostile_trajectory(name, s.scene);
  sh::ProxyParameters p;
  p.radius_mm = 4;
  p.max_work = int(state.range(1));
  sh::SphereProxyRenderer renderer(p);
  const sh::ScenePoses poses{};
  const double T = 1e-3;
  double t = 0;
  renderer.reset(path.position_at(0));
  std::vector<double> us;
  int max_work = 0;
  std::int64_t bounded = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    sh::ProbeState probe{path.position_at(t), path.velocity_at(t)};
    const auto out = renderer.render(probe, s.scene, poses, T);
    us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
                     .count());
    benchmark::DoNotOptimize(out);
    max_work = std::max(max_work, out.work);
    bounded += out.truncated;
    t += T;
    if (t > path.duration_s()) {
      t = 0;
      renderer.reset(path.position_at(0));
    }
  }
  std::sort(us.begin(), us.end());
  state.SetLabel(name);
  state.counters["p999_us"] = us[std::min(us.size() - 1, std::size_t(0.999 * double(us.size())))];
  state.counters["max_us"] = us.back();
  state.counters["max_work"] = max_work;
  state.counters["at_bound"] = double(bounded) / double(state.iterations());
}
BENCHMARK(HostileProxyTick)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5}, {4096}})
    ->Args({2, 256})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

void DiscPalpationStep(benchmark::State& state) {
  sm::MeshOptions mo;
  mo.cell_size_mm = 0.1 * double(state.range(0));
  const sm::TetMesh m =
      sm::mesh_parametric_disc(sm::disc_dimensions("L4-L5", SPINESIM_DATA_DIR), mo,
                               sm::disc_frame_in_spine("L4-L5", SPINESIM_DATA_DIR));
  spinesim::mss::MssOptions o;
  o.volume_term = true;
  o.fibre_springs = state.range(2) != 0;
  const spinesim::mss::MssModel model(
      m, sm::load_material(o.fibre_springs ? "fibre-reinforced" : "real-disc", SPINESIM_DATA_DIR),
      o);
  spinesim::mss::Boundary bc;
  bc.plate_center_mm = spinesim::mss::default_plate_center(m);
  sh::DiscPalpationOptions po;
  po.realtime_priority = false;
  sh::DiscPalpation p(model, bc, po);
  // The anterior wall at mid-height (as studies::disc_anterior_wall).
  const Eigen::MatrixX3d local = (m.V.rowwise() - m.frame.origin_mm.transpose()) * m.frame.axes;
  const double mid = 0.5 * (local.col(1).maxCoeff() + local.col(1).minCoeff());
  const double h = local.col(1).maxCoeff() - local.col(1).minCoeff();
  Eigen::Index best = -1;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (std::abs(local(i, 1) - mid) < h / 6 && (best < 0 || local(i, 2) > local(best, 2))) best = i;
  const Eigen::Vector3d wall = m.V.row(best).transpose(), n = m.frame.axes.col(2);
  const bool pressed = state.range(1) != 0;
  for (int k = 0; k <= 100; ++k)  // approach and press in, untimed
    p.step(wall + (4.0 + 10.0 - (pressed ? 12.0 : 0.0) * k / 100.0) * n);
  const Eigen::Vector3d device = wall + (pressed ? 2.0 : 14.0) * n;
  for (auto _ : state) benchmark::DoNotOptimize(p.step(device).force_n);
  state.counters["tets"] = double(m.num_tets());
}
BENCHMARK(DiscPalpationStep)
    ->ArgsProduct({{20, 25, 30, 40}, {0, 1}, {0}})
    ->ArgsProduct({{40}, {0, 1}, {1}})
    ->Unit(benchmark::kMicrosecond)
    ->Iterations(500);

BENCHMARK_MAIN();
