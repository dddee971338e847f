#include "framework/api/log_channel.hpp"

#include <deque>
#include <mutex>
#include <stdexcept>
#include <string>

namespace gem {

namespace {
std::mutex g_mutex;
std::deque<LogWriter> g_writers;  // a deque: a writer's address never moves while others are added
}  // namespace

int openLogChannel(LogWriter writer) {
  std::lock_guard lock(g_mutex);
  g_writers.push_back(std::move(writer));
  return static_cast<int>(g_writers.size()) - 1;
}

void deliverLogs(const LogRecord* records, int count) {
  if (count == 0) return;
  const LogWriter* writer = nullptr;
  int channel = -1;
  for (int k = 0; k < count; ++k) {
    if (records[k].channel != channel) {
      std::lock_guard lock(g_mutex);
      channel = records[k].channel;
      if (channel < 0 || channel >= static_cast<int>(g_writers.size()))
        throw std::logic_error("log record for unknown channel " + std::to_string(channel));
      writer = &g_writers[static_cast<size_t>(channel)];
    }
    (*writer)(records[k]);
  }
}

void deliverLogs(const StepRecords& records) {
  const std::vector<LogRecord> logs = records.rows(RecordStream<LogRecord>{kLogStream});
  deliverLogs(logs.data(), static_cast<int>(logs.size()));
}

}  // namespace gem
