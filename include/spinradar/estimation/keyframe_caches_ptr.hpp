#pragma once
// KeyframeTracker's caches (src/estimation/keyframe_caches.hpp: work reused at keyframe
// switches) behind a pointer, so that the public header does not carry them.
#include <memory>

namespace spinradar {

struct KeyframeCaches;  // src/estimation/keyframe_proximity.cpp
struct SolveTermCache;  // src/estimation/keyframe_caches.hpp
struct DescriptorScreen;  // src/estimation/keyframe_caches.hpp
/// Owns the tracker's caches (work reused at keyframe switches); a copy starts without them.
class KeyframeCachesPtr {
 public:
  KeyframeCachesPtr();
  ~KeyframeCachesPtr();
  KeyframeCachesPtr(const KeyframeCachesPtr&);
  KeyframeCachesPtr& operator=(const KeyframeCachesPtr&);
  KeyframeCaches* operator->() const { return p_.get(); }

 private:
  std::unique_ptr<KeyframeCaches> p_;
};

}  // namespace spinradar
