// The rigid scene the haptic probe touches: the spine's 18 bodies (T1…L5 and the sacrum), one
// vertebra (L3) or a plane, with the vertebra surfaces from one of three sources:
//   generated — the parametric vertebrae (mesh/vertebra_geometry.hpp), the embedded default;
//   real      — the ArtiSynth lumbosacral surfaces (L1–L5, sacrum; Visible Human Male) from the
//               shared test data, registered to the model's lumbar frames by one rigid motion;
//               the thoracic levels fall back to the generated ones;
//   SCENE.json — a user's surfaces (e.g. CT-segmented), each with its transform into its
//               vertebra's frame; the levels it leaves out are generated.
// Every surface is placed at the spine model's reference posture, in the global frame (mm).
#pragma once

#include "spinesim/haptics/scene.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace spinesim::haptics {

struct HapticSceneRequest {
  std::string scene = "spine";  ///< spine (T1…L5 + sacrum), vertebra (L3), disc (its two) or plane
  std::string level = "L4-L5";  ///< disc: the level whose two vertebrae are the rigid bodies
  std::string vertebrae = "generated";  ///< generated, real, or a scene JSON file
  int triangles = 6000;                 ///< per generated body
  std::string testdata_dir;             ///< for `real`: the folder holding artisynth-lss/
  /// Where generated vertebrae are kept between runs (mesh/vertebra_cache.hpp); empty: mesh
  /// them every time.
  std::string cache_dir;
  /// spine: also the rib cage (spine/rib_cage.hpp), bodies R1, L1, …, R12, L12 and "sternum":
  /// tubes through each rib's points, with its cartilage to where that ends.
  bool rib_cage = false;
  /// spine: a scoliotic spine (spine/scoliosis.hpp; cobb_deg 0: straight), its vertebrae placed
  /// in the curve's rest posture (the sacrum stays).
  spine::ScoliosisCurve scoliosis;
  /// spine: the body (zeros: the reference body); every surface is scaled with its lengths.
  spine::Subject subject;
};

/// How the real vertebrae were registered: one rigid motion (a rotation about the lateral axis
/// and a translation, the lateral axis kept) that brings the real bodies' centroids nearest, in
/// the least-squares sense, to the model's body centres L1…L5 and S1.
struct Registration {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  std::vector<std::string> names;
  std::vector<double> residual_mm;  ///< per body: |registered real centre − model centre|
  double rms_mm = 0;
};

struct HapticScene {
  haptics::Scene scene;
  std::string description;
  std::vector<std::string> sources;  ///< per body: "generated", "real", or the file
  int cached = 0;                    ///< generated bodies read from the cache
  Eigen::Vector3d center_mm = Eigen::Vector3d::Zero();
  bool registered = false;
  Registration registration;
  double seconds = 0;
};

/// Throws std::invalid_argument (one line) unless `scene` is spine, vertebra, disc or plane.
void check_scene_name(const std::string& scene);

/// Builds the scene; `progress(done, total)` per body. Throws std::invalid_argument (one line)
/// for an unknown scene or source, a missing test-data folder (for `real`), or a bad scene file.
HapticScene build_haptic_scene(const HapticSceneRequest& r, const std::string& data_dir,
                               const std::function<void(int, int)>& progress = {});

/// The registration of the real lumbosacral vertebrae (no meshing): for reports and tests.
/// Throws std::invalid_argument when `testdata_dir`/artisynth-lss is absent.
Registration register_real_vertebrae(const std::string& testdata_dir, const std::string& data_dir);

nlohmann::json registration_json(const Registration& r);

}  // namespace spinesim::haptics
