#pragma once
// Which drive separates two effects whose residual signatures this data cannot tell apart
// (physics-signatures.md, section 3).
#include <string>

#include "spinradar/diagnose/predict.hpp"

namespace spinradar::diagnose {

/// A sentence naming the manoeuvre / data that breaks the tie between a and b.
std::string separatingDrive(Effect a, Effect b);

/// One line on what the effect's residual signature looks like.
std::string signatureOf(Effect e);

}  // namespace spinradar::diagnose
