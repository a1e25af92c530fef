// The whole public API of the softsight library in one include:
//   #include <softsight/softsight.h>
// with find_package(softsight) and softsight::softsight, or `pkg-config --cflags --libs softsight`.
// A program that uses one part can include that part's headers alone and link only its library
// (softsight::track, `pkg-config softsight-track`, ...): docs/api.md lists them.
#pragma once

#include "softsight/version.h"

// core: value types (Frame, Observation, Measurement, FrameResult), errors, number formatting.
#include "softsight/core/error.h"
#include "softsight/core/file_write.h"
#include "softsight/core/format.h"
#include "softsight/core/hsv_range.h"
#include "softsight/core/option_table.h"
#include "softsight/core/types.h"

// geometry: the paper's measurements on marker positions, circle fit, 3D shape.
#include "softsight/geometry/circle_fit.h"
#include "softsight/geometry/measurement.h"
#include "softsight/geometry/shape3d.h"
#include "softsight/geometry/triangle.h"

// track: the Tracker interface, its parameters, the registry of kinds, the colour and template
// trackers, colour picking and init's marker finder.
#include "softsight/track/colour_tracker.h"
#include "softsight/track/hsv_picker.h"
#include "softsight/track/marker_finder.h"
#include "softsight/track/template_tracker.h"
#include "softsight/track/tracker.h"
#include "softsight/track/tracker_kind.h"

// sim: the renderers with exact ground truth and the truth scorer.
#include "softsight/sim/builtin_scenes.h"
#include "softsight/sim/chessboard.h"
#include "softsight/sim/plate_scene.h"
#include "softsight/sim/scene.h"
#include "softsight/sim/stereo_scene.h"
#include "softsight/sim/truth_score.h"

// calib: camera and stereo calibration, triangulation.
#include "softsight/calib/board_frame.h"
#include "softsight/calib/camera_calibration.h"
#include "softsight/calib/stereo_calibration.h"
#include "softsight/calib/triangulation.h"

// control: the outer-loop controller, the board link and its transports, the simulated rig.
#include "softsight/control/actuator_model.h"
#include "softsight/control/board_config.h"
#include "softsight/control/board_link.h"
#include "softsight/control/control_config.h"
#include "softsight/control/controller.h"
#include "softsight/control/profile.h"
#include "softsight/control/rig.h"
#include "softsight/control/session.h"
#include "softsight/control/transport.h"

// io: frame sources and writers, the CSV column table, writer and reader, plots.
#include "softsight/io/async_frame_writer.h"
#include "softsight/io/camera_settings.h"
#include "softsight/io/csv_columns.h"
#include "softsight/io/csv_reader.h"
#include "softsight/io/csv_writer.h"
#include "softsight/io/frame_offset.h"
#include "softsight/io/frame_source.h"
#include "softsight/io/frame_writer.h"
#include "softsight/io/output_guard.h"
#include "softsight/io/plot.h"
#include "softsight/io/run_source.h"
#include "softsight/io/stereo_input.h"
#include "softsight/io/truth_csv.h"

// config: the YAML configuration: reading, writing, checking.
#include "softsight/config/config.h"
#include "softsight/config/control_config.h"

// pipeline: TrackingSession, RunPipeline, the sinks and the run's summary, two cameras.
#include "softsight/pipeline/hook.h"
#include "softsight/pipeline/run.h"
#include "softsight/pipeline/sink.h"
#include "softsight/pipeline/sinks.h"
#include "softsight/pipeline/status_summary.h"
#include "softsight/pipeline/stereo_session.h"
#include "softsight/pipeline/summary.h"
#include "softsight/pipeline/tracking_session.h"
