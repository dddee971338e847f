// Log channels: how an event writes rows of its own (a CSV of detections, say) from code that runs
// on either backend. Parsing its Params, the event opens a channel with the writer that will get
// its rows and keeps the channel number in its Params (plain data, so it reaches the device); its
// apply() pushes LogRecords into the step's RecordSink; after each step the backend hands every
// record to its channel's writer on the host, in contact order. The writer runs on the thread that
// steps the simulation, never concurrently for one channel.
#pragma once
#include <functional>
#include <vector>

#include "framework/api/event_api.hpp"
#include "framework/api/step_records.hpp"

namespace gem {

using LogWriter = std::function<void(const LogRecord&)>;

// A new channel for this writer (thread-safe: sweeps parse their cases on several threads). The
// writer lives as long as the process: channels are few (one per parsed event instance).
int openLogChannel(LogWriter writer);

// Hands each record to its channel's writer. An unknown channel is a logic error (throws).
void deliverLogs(const LogRecord* records, int count);
// Hands the log stream's rows of a step (stream 0) to their channels' writers, in order.
void deliverLogs(const StepRecords& records);

}  // namespace gem
