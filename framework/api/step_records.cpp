#include "framework/api/step_records.hpp"

#include <stdexcept>

namespace gem {

int RecordStreams::find(const std::string& name) const {
  for (int k = 0; k < count(); ++k)
    if (m_streams[static_cast<size_t>(k)].name == name) return k;
  return -1;
}

int RecordStreams::openBytes(const std::string& name, int recordSize, int stride) {
  const int existing = find(name);
  if (existing >= 0) {
    if (m_streams[static_cast<size_t>(existing)].recordSize != recordSize)
      throw std::logic_error("record stream \"" + name + "\" opened with records of " + std::to_string(recordSize) + " bytes and of " +
                             std::to_string(m_streams[static_cast<size_t>(existing)].recordSize) + ": two events disagree on its type");
    return existing;
  }
  if (count() == kMaxRecordStreams)
    throw std::logic_error("record stream \"" + name + "\": a run holds at most " + std::to_string(kMaxRecordStreams) + " streams");
  m_streams.push_back({name, recordSize, stride});
  return count() - 1;
}

void StepRecords::reset(const RecordStreams& streams) {
  m_streams = &streams;
  m_rows.assign(static_cast<size_t>(streams.count()), {});
}

void StepRecords::append(int stream, const unsigned char* rows, int count) {
  std::vector<unsigned char>& to = m_rows[static_cast<size_t>(stream)];
  to.insert(to.end(), rows, rows + static_cast<size_t>(count) * static_cast<size_t>(strideOf(stream)));
}

void StepRecords::clear() {
  for (auto& rows : m_rows) rows.clear();
}

}  // namespace gem
