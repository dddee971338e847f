// The host side of record streams (framework/api/record_stream.hpp): the streams a run opened
// (RecordStreams, filled while the events' Params are parsed) and the rows of the last step
// (StepRecords, what a stepper hands out after each step, in the CPU's order).
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "framework/api/record_stream.hpp"

namespace gem {

struct RecordStreamInfo {
  std::string name;
  int recordSize;        // bytes of one record
  int stride;            // bytes of one row: tag + record, rounded up to 8
  std::string openedBy;  // who opened it first (setOpener), for a message about a clash
};

// The streams of one run, numbered from 0 (the log channels' stream) in the order they were opened.
class RecordStreams {
 public:
  RecordStreams() { openBytes("log", sizeof(LogRecord), recordStride<LogRecord>()); }

  // Opens the stream `name` for records of type Record, or returns the one already open under that
  // name. A second type of another size under one name, or a stream past kMaxRecordStreams, is an
  // InputError naming the events (setOpener) that disagree: stream names are one namespace for
  // built-in and plugin events alike.
  template <class Record>
  RecordStream<Record> open(const std::string& name) {
    static_assert(std::is_trivially_copyable_v<Record>, "a record is plain data: it is copied as bytes from the device");
    return RecordStream<Record>{openBytes(name, sizeof(Record), recordStride<Record>())};
  }
  int count() const { return static_cast<int>(m_streams.size()); }
  const RecordStreamInfo& info(int stream) const { return m_streams[static_cast<size_t>(stream)]; }
  int find(const std::string& name) const;  // -1 when not open
  // Who opens the streams from now on, as a message names them ("FILE:LINE:COL: events.NAME (plugin
  // ORIGIN)"): the stepper sets it before each event's parse.
  void setOpener(std::string opener) { m_opener = std::move(opener); }

 private:
  int openBytes(const std::string& name, int recordSize, int stride);
  std::vector<RecordStreamInfo> m_streams;
  std::string m_opener = "GEM";
};

// The rows one step produced, stream by stream, in the CPU's order: by event (their declared
// order), then by contact. Records are copied out; rows never move while the step is read.
class StepRecords {
 public:
  void reset(const RecordStreams& streams);
  const RecordStreams& streams() const { return *m_streams; }
  int rowCount(int stream) const {
    return stream < 0 || stream >= static_cast<int>(m_rows.size())
               ? 0
               : static_cast<int>(m_rows[static_cast<size_t>(stream)].size()) / strideOf(stream);
  }
  const RecordTag& tag(int stream, int row) const { return *reinterpret_cast<const RecordTag*>(rowBytes(stream, row)); }
  const void* record(int stream, int row) const { return rowBytes(stream, row) + sizeof(RecordTag); }

  template <class Record>
  std::vector<Record> rows(RecordStream<Record> stream) const {
    std::vector<Record> out(static_cast<size_t>(rowCount(stream.index)));
    for (size_t k = 0; k < out.size(); ++k) std::memcpy(&out[k], record(stream.index, static_cast<int>(k)), sizeof(Record));
    return out;
  }
  // By name: empty when the run has no such stream (its event is off, say).
  template <class Record>
  std::vector<Record> rows(const std::string& name) const {
    return m_streams ? rows(RecordStream<Record>{m_streams->find(name)}) : std::vector<Record>{};
  }

  // The drivers' side: rows of `stream` appended as they are (tag first), `count` of them.
  void append(int stream, const unsigned char* rows, int count);
  void clear();

 private:
  int strideOf(int stream) const { return m_streams->info(stream).stride; }
  const unsigned char* rowBytes(int stream, int row) const {
    return m_rows[static_cast<size_t>(stream)].data() + static_cast<size_t>(row) * static_cast<size_t>(strideOf(stream));
  }
  const RecordStreams* m_streams = nullptr;
  std::vector<std::vector<unsigned char>> m_rows;
};

}  // namespace gem
