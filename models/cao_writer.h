// Writes ViSP's .cao format (V1): points, 3D lines and faces from points, with full precision, so
// that ViSP reads back exactly the coordinates linetrack holds. Used to hand ViSP's tracker the
// model with its faces oriented.
#pragma once

#include <string>

#include "models/cao_reader.h"
#include "models/wireframe.h"

namespace linetrack {

// The .cao text of `cao` (its includes already resolved): points, lines, faces from points; no
// cylinders or circles. `title` becomes a comment line.
std::string CaoText(const CaoModel& cao, const std::string& title);

// `cao` with its faces as `model` (built from `cao` by WireframeModel::FromCao) oriented them: a
// flipped face's points reversed, a two-sided face followed by its reversed copy (ViSP draws a
// face from its front side only).
CaoModel OrientedCao(const CaoModel& cao, const WireframeModel& model);

}  // namespace linetrack
