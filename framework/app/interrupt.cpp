#include "framework/app/interrupt.hpp"

#include <csignal>

#include <fmt/format.h>

namespace gem {

namespace {
volatile std::sig_atomic_t g_signal = 0;
extern "C" void onInterrupt(int signal) { g_signal = signal; }
}  // namespace

void catchInterrupts() {
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
}

int interruptSignal() { return g_signal; }

void stopIfInterrupted(long step) {
  const int signal = g_signal;
  if (signal == 0) return;
  throw Interrupted(
      signal,
      fmt::format("interrupted ({}) after step {}: the files written so far are kept, whole; summary.json says \"completed\": false",
                  signal == SIGINT ? "Ctrl-C" : "SIGTERM", step));
}

}  // namespace gem
