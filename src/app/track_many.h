// `softsight track` with several inputs: one CSV per input in an output folder, `jobs` inputs at a
// time, each in its own `softsight track` process.
//
// Processes, not threads: FFmpeg's log, through which a damaged frame is recognised
// (io/decoder_log.h), is one per process, so two videos decoded by threads of one process could
// not tell whose frame was damaged; a process also keeps one input's crash or exhausted memory
// from the others. Each child is this program run on one input with the same options, so its CSV
// is the CSV a single-input run writes.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "app/track_command.h"

namespace softsight {

struct TrackManyOptions {
  // The options every input shares (config, method, gray/colour, fps, max frames, quiet);
  // `source.input` and `csv_file` are set per input.
  TrackOptions common;
  std::vector<std::string> inputs;
  std::string out_dir;  // Created when absent.
  int jobs = 1;         // Inputs tracked at the same time (>= 1).
  // The program a child runs ("/proc/self/exe": this one).
  std::string program = "/proc/self/exe";
};

// The CSV each input gets in `out_dir`: the input's file name without its extension ("run.avi"
// -> run.csv; a folder's name; "synth:bending" -> synth_bending.csv; '%' removed), "-1", "-2"
// ... added to a name already taken, so no two inputs share a CSV. Python's
// softsight.batch.track_many names its CSVs the same way.
std::vector<std::string> CsvNamesForInputs(const std::vector<std::string>& inputs,
                                           const std::string& out_dir);

// Tracks every input and writes one line per input as it finishes to `report` ("track: [2/4]
// b.avi -> out/b.csv: 300 frames (end of input), ..." or its error line), then a final line.
// An input that fails does not stop the others. Returns the exit code: 0 when every input
// succeeded, 128 + signal when a stop (Ctrl-C) ended the run (inputs not started are skipped),
// else the exit code of the first input that failed (2 for bad input). Throws InputError before
// anything runs for what concerns every input (the config, the output folder, a CSV that would
// overwrite an input).
int RunTrackMany(const TrackManyOptions& options, std::ostream& report);

}  // namespace softsight
