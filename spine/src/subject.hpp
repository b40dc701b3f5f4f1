// A spine for a given body (spine/README.md, "A spine for a given body"): the reference body's
// model scaled to a subject's height, mass and sex. Internal to spinesim::spine (model.cpp).
#pragma once

#include "spinesim/spine/model.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace spinesim::spine::detail {

/// Resolves `subject` against the reference body of spine_model.json (`config`, read from
/// `file`): a zero height or mass becomes the reference's. Returns the scale factors and fills
/// `percent` with the sex's segment masses. Throws std::invalid_argument (one line) for a
/// height, mass or body-mass index outside the range the scaling laws are applied to.
SubjectScale subject_scale(const nlohmann::json& config, const std::string& file,
                           Subject& subject, SegmentMassPercent& percent);

/// Scales every length of `m` (vertebra centres, joint points, line elements' attachments and
/// rest lengths, load points, the bushing's point, the chest) by scale.length about the origin,
/// the joints' rotational stiffness by its cube, the ligaments' axial stiffness by it, and every
/// muscle's pCSA by scale.muscle. Masses and the bushing's stiffness are set where they are
/// built (load_weights, iap_from_appendix_c). With every factor 1 nothing changes, bit for bit.
void scale_to_subject(SpineModel& m, const SubjectScale& scale);

}  // namespace spinesim::spine::detail
