// Ctrl-C and SIGTERM: a run stops at the end of the step it is in, keeps every file it wrote whole
// under its final name, says so, and gem exits 128 + the signal's number (130, 143). The handler
// only sets a flag; the run loops read it between steps, and the run writes its summary.json with
// "completed": false.
#pragma once
#include <stdexcept>
#include <string>

namespace gem {

// Installs the handlers (gem's main, once).
void catchInterrupts();
// The signal received, or 0.
int interruptSignal();
// Throws Interrupted when a signal was received.
void stopIfInterrupted(long step);

class Interrupted : public std::runtime_error {
 public:
  Interrupted(int signal, const std::string& message) : std::runtime_error(message), m_signal(signal) {}
  int signal() const { return m_signal; }

 private:
  int m_signal;
};

}  // namespace gem
