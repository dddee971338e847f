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
  // A closed terminal (SIGHUP) stops the run as SIGTERM does, with a checkpoint and whole files:
  // it once killed the run outright. Unless SIGHUP is ignored (`nohup gem run ...`): then the run
  // is meant to outlive its terminal, and goes on.
  if (std::signal(SIGHUP, onInterrupt) == SIG_IGN) std::signal(SIGHUP, SIG_IGN);
  // A reader of the terminal report that goes away (`gem run ... | head`) must not kill the run in
  // the middle of its files: the report's writes fail instead, and the run ends as it would have,
  // with the exit status its gem.log records (it once exited 141 where gem.log said 0).
  std::signal(SIGPIPE, SIG_IGN);
}

int interruptSignal() { return g_signal; }

void stopIfInterrupted(long step) {
  const int signal = g_signal;
  if (signal == 0) return;
  throw Interrupted(
      signal,
      fmt::format("interrupted ({}) after step {}: the files written so far are kept, whole; summary.json says \"completed\": false",
                  signal == SIGINT   ? "Ctrl-C"
                  : signal == SIGHUP ? "SIGHUP"
                                     : "SIGTERM",
                  step));
}

}  // namespace gem
