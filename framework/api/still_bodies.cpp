#include "framework/api/still_bodies.hpp"

namespace gem {

namespace {
thread_local const char* t_still = nullptr;
}

StillBodiesScope::StillBodiesScope(const char* flags) : m_previous(t_still) { t_still = flags; }

StillBodiesScope::~StillBodiesScope() { t_still = m_previous; }

const char* stillBodies() { return t_still; }

}  // namespace gem
