#pragma once
// Which drive separates two effects whose residual signatures this data cannot tell apart
// (physics-signatures.md, section 3).
#include <string>

#include "spinradar/diagnose/predict.hpp"

namespace spinradar::diagnose {

/// A sentence naming the manoeuvre / data that breaks the tie between a and b.
std::string separatingDrive(Effect a, Effect b);

/// Without a world file: the map/test split (or drive) under which the mapped positions do not
/// carry the effect the way the test views see it, so that it becomes visible.
std::string revealingSplit(Effect e);

/// One line on what the effect's residual signature looks like.
std::string signatureOf(Effect e);

}  // namespace spinradar::diagnose
