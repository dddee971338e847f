#include "framework/api/step_records.hpp"

#include <fmt/format.h>

#include "framework/api/errors.hpp"

namespace gem {

int RecordStreams::find(const std::string& name) const {
  for (int k = 0; k < count(); ++k)
    if (m_streams[static_cast<size_t>(k)].name == name) return k;
  return -1;
}

int RecordStreams::openBytes(const std::string& name, int recordSize, int stride) {
  const int existing = find(name);
  if (existing >= 0) {
    const RecordStreamInfo& first = m_streams[static_cast<size_t>(existing)];
    if (first.recordSize != recordSize)
      throw InputError(
          fmt::format("{}: opens the record stream \"{}\" with records of {} bytes, but {} opened it with records of {} "
                      "bytes: events that share a stream name share its record type (give a stream of your own a name "
                      "of its own; the built-in streams are \"log\", \"impacts\" and \"breaks\")",
                      m_opener, name, recordSize, first.openedBy, first.recordSize));
    return existing;
  }
  if (count() == kMaxRecordStreams)
    throw InputError(fmt::format("{}: opens the record stream \"{}\", but a run holds at most {} record streams, and {} are open ({})",
                                 m_opener, name, kMaxRecordStreams, count(), [&] {
                                   std::string names;
                                   for (const RecordStreamInfo& s : m_streams) names += (names.empty() ? "" : ", ") + s.name;
                                   return names;
                                 }()));
  m_streams.push_back({name, recordSize, stride, m_opener});
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
