// Record streams: typed rows that two-body events append during a step (ship_impact's impact log,
// its requests to break a floe, a plugin's detections), on either backend. The event that owns a
// record type declares it (events/ship_impact.hpp: ImpactRecord); the framework only moves bytes.
//
//   - When its Params are parsed, an event opens the streams it writes or reads by name,
//     `p.impacts = config.records.open<ImpactRecord>("impacts")`, and keeps the handle in its Params
//     (plain data, so it reaches the device). Events that name the same stream share it.
//   - In apply() it pushes rows: `sink.push(p.impacts, record)`. The driver stamps each row with
//     where it came from (RecordTag: the event's place in the phase, the contact, the case), so that
//     the host can put the rows of a step in the CPU's order, event by event and contact by contact,
//     whatever order device threads pushed them in.
//   - After the step the stepper hands them out (StepRecords, framework/api/step_records.hpp): to
//     the topology events, to the run folder's writers (an event registers one per stream it wants
//     written: impacts.csv comes from ship_impact), to a log channel's writer (stream 0).
//
// Host and device: plain data, no std containers.
#pragma once
#include <cstdint>
#include <cstring>

#include "geometry/config.hpp"

namespace gem {

// At most this many streams in one run; stream 0 is the log channels' (LogRecord).
constexpr int kMaxRecordStreams = 8;
constexpr int kLogStream = 0;

// A handle to an open stream of records of type Record; index -1: not opened (push does nothing).
template <class Record>
struct RecordStream {
  int index = -1;
};

// Where a row came from, written before it: the order of the rows of a step is (event, contact).
struct RecordTag {
  std::int32_t event;    // the event's place among the phase's events (their declared order)
  std::int32_t contact;  // the contact's index in the step
  std::int32_t world;    // the case, when a device state runs several (0 alone)
  std::int32_t unused;
};

// One stream's storage for a step (or a device batch of steps): `capacity` rows of `stride` bytes,
// each a RecordTag then the record. count counts every push, past the capacity too: the driver grows
// the buffer and runs the phase again, so a step never writes out of bounds.
struct RecordBuffer {
  unsigned char* rows;
  int stride;
  int capacity;
  int* count;
};

// The bytes a row of Record takes: the tag, then the record, rounded up to 8.
template <class Record>
constexpr int recordStride() {
  return static_cast<int>((sizeof(RecordTag) + sizeof(Record) + 7) / 8 * 8);
}

// A row that an event logs for its own output (a plugin's detector, say): the channel it was given
// when its Params were parsed (framework/api/log_channel.hpp), the two bodies and up to six numbers.
// The host hands each one to its channel's writer after the step, in order, on either backend.
struct LogRecord {
  int channel;
  Real time;
  std::int64_t idA, idB;
  Real value[6];
};

// What a two-body event pushes into. The CPU driver points the buffers at host memory, a device
// driver at device memory (an integer atomic counter per stream; no floating-point atomics).
struct RecordSink {
  RecordBuffer streams[kMaxRecordStreams];
  RecordTag tag;

  // This sink stamped for contact `contact` of the event at `event`, in case `world`.
  GEM_HD RecordSink at(int event, int contact, int world) const {
    RecordSink s = *this;
    s.tag = RecordTag{event, contact, world, 0};
    return s;
  }

  template <class Record>
  GEM_HD void push(RecordStream<Record> stream, const Record& record) const {
    if (stream.index < 0 || stream.index >= kMaxRecordStreams) return;
    const RecordBuffer& b = streams[stream.index];
    const int k = next(b.count);
    if (k >= b.capacity) return;
    unsigned char* row = b.rows + static_cast<std::size_t>(k) * static_cast<std::size_t>(b.stride);
    std::memcpy(row, &tag, sizeof tag);
    std::memcpy(row + sizeof(RecordTag), &record, sizeof record);
  }
  // A log channel's row (framework/api/log_channel.hpp).
  GEM_HD void push(const LogRecord& record) const { push(RecordStream<LogRecord>{kLogStream}, record); }

  GEM_HD static int next(int* counter) {
#if defined(__CUDA_ARCH__)
    return atomicAdd(counter, 1);
#else
    return (*counter)++;
#endif
  }
};

}  // namespace gem
