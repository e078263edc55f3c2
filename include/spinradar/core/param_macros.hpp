#pragma once
// Machinery that turns one X-macro list of parameters into a config struct with in-class
// defaults plus a visitor. Every list entry is exactly one line of the form
//   X(type, name, default, min, max, "unit", "doc")
// so that cfg/*.cfg (dynamic_reconfigure) and the README table generator can read the same
// definition. min/max are ignored for bool and std::string.
#include <string>

namespace spinradar {

struct ParamMeta {
  const char* name;
  const char* unit;
  const char* doc;
  double min;
  double max;
};

}  // namespace spinradar

#define SPINRADAR_PARAM_FIELD(type, name, def, lo, hi, unit, doc) type name = def;
#define SPINRADAR_PARAM_VISIT(type, name, def, lo, hi, unit, doc) \
  f(::spinradar::ParamMeta{#name, unit, doc, double(lo), double(hi)}, name);

/// Declares the fields and `template <class F> void visit(F&& f)` (also const) for LIST.
#define SPINRADAR_DECLARE_PARAMS(LIST)                   \
  LIST(SPINRADAR_PARAM_FIELD)                            \
  template <class F>                                     \
  void visit(F&& f) {                                    \
    LIST(SPINRADAR_PARAM_VISIT)                          \
  }                                                      \
  template <class F>                                     \
  void visit(F&& f) const {                              \
    LIST(SPINRADAR_PARAM_VISIT)                          \
  }
