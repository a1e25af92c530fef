// `softsight listen ENDPOINT`: the receiving end of `--publish` on the command line. Prints each
// record as a CSV row (or its JSON), or writes a CSV file through the CSV writer, until the run
// ends (its "end" record), --count records, --timeout-s of silence or Ctrl-C.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>

namespace softsight {

struct ListenOptions {
  std::string endpoint;              // tcp://HOST:PORT or ipc://PATH, as the run's --publish.
  std::string topic = "frame";       // frame, measure, marker/<name> (docs/stream.md).
  std::string csv_file;              // Write the records here; empty: print them.
  bool json = false;                 // Print each record's JSON as it came, one per line.
  std::optional<int64_t> count;      // Stop after this many records.
  std::optional<double> timeout_s;   // Fail when nothing at all arrives for this long.
  bool quiet = false;                // Nothing on stderr but errors.
  // Polled every 100 ms: true stops listening (Ctrl-C; a test's own condition).
  std::function<bool()> stop_requested;
};

struct ListenSummary {
  int64_t records = 0;              // Of the topic, received.
  int64_t hellos = 0;
  int64_t frame_gaps = 0;           // Frame numbers missing between consecutive records.
  int64_t before_hello = 0;         // Records that came before any hello: left out.
  bool ended = false;               // The run's "end" record arrived.
  std::string end_record;           // Its JSON.
};

// The run's end record as `listen` prints it, in the words the run's own summary printed:
// "the run ended: 120 frames (duration reached), 122 messages sent, 0 dropped" (and the error,
// when there was one). A body that is not such a record is shown as it came.
std::string DescribeEndRecord(const std::string& body);

// Runs until one of the ends above. Records go to `out` (unless csv_file), the hello and the end
// to `err` (unless quiet). Throws InputError: a malformed endpoint, a publisher of another
// format version, a record that is not JSON, the timeout, an unwritable CSV (rows written before
// stay).
ListenSummary RunListen(const ListenOptions& options, std::ostream& out, std::ostream& err);

}  // namespace softsight
