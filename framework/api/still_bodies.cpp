#include "framework/api/still_bodies.hpp"

namespace gem {

namespace {
thread_local const char* t_still = nullptr;
thread_local std::vector<CandidateRange>* t_resting = nullptr;
}  // namespace

StillBodiesScope::StillBodiesScope(const char* flags) : m_previous(t_still) { t_still = flags; }

StillBodiesScope::~StillBodiesScope() { t_still = m_previous; }

const char* stillBodies() { return t_still; }

RestingPairsScope::RestingPairsScope(std::vector<CandidateRange>* ranges) : m_previous(t_resting) { t_resting = ranges; }

RestingPairsScope::~RestingPairsScope() { t_resting = m_previous; }

std::vector<CandidateRange>* restingPairs() { return t_resting; }

}  // namespace gem
