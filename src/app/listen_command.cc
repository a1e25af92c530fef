#include "app/listen_command.h"

#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include "app/cli_checks.h"
#include "app/commands.h"
#include "app/shared_flags.h"
#include "app/stop_request.h"
#include "softsight/core/error.h"
#include "softsight/core/format.h"
#include "softsight/io/csv_writer.h"
#include "stream/stream_format.h"
#include "stream/subscriber.h"

namespace softsight {
namespace {

using Json = nlohmann::ordered_json;

// The slice of each wait: how often Ctrl-C is noticed.
constexpr int kPollSliceMs = 100;

// The text of each number among a record's own fields (the object's first level), as the
// message has it: the publisher sends the CSV's field ("1.0000"), and a parsed double would print
// as "1.0", so `listen --csv` would differ from the run's CSV. nlohmann's SAX interface hands
// over a float's text; an integer's text is its value's.
class RecordNumberTexts : public nlohmann::json_sax<Json> {
 public:
  // Fills `texts` (field name -> the number's text); false when the body does not parse.
  static bool Read(const std::string& body, std::map<std::string, std::string>& texts) {
    texts.clear();
    RecordNumberTexts reader(texts);
    return Json::sax_parse(body, &reader, nlohmann::json::input_format_t::json, /*strict=*/true,
                           /*ignore_comments=*/false);
  }

  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t value) override {
    return keep(std::to_string(value));
  }
  bool number_unsigned(number_unsigned_t value) override {
    return keep(std::to_string(value));
  }
  bool number_float(number_float_t, const string_t& text) override { return keep(text); }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return ++depth_, true; }
  bool key(string_t& name) override { return key_ = name, true; }
  bool end_object() override { return --depth_, true; }
  bool start_array(std::size_t) override { return ++depth_, true; }
  bool end_array() override { return --depth_, true; }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;
  }

 private:
  explicit RecordNumberTexts(std::map<std::string, std::string>& texts) : texts_(texts) {}
  bool keep(const std::string& text) {
    if (depth_ == 1) texts_[key_] = text;
    return true;
  }
  std::map<std::string, std::string>& texts_;
  std::string key_;
  int depth_ = 0;
};

// A record's value as the CSV field: null -> empty, a number as the message wrote it (`text`,
// the CSV's own digits), a string as it is (the publisher's rule, stream_format.h, read
// backwards).
std::string FieldText(const Json& value, const std::string* text) {
  if (value.is_null()) return "";
  if (value.is_string()) return value.get<std::string>();
  if (value.is_boolean()) return value.get<bool>() ? "1" : "0";
  return text != nullptr ? *text : value.dump();
}

// The records as CSV rows: the columns are the first record's keys, in its order; each column
// writes the current record's field (CsvWriter and the column table, as every CSV here).
class RecordTable {
 public:
  explicit RecordTable(const Json& first) {
    for (const auto& item : first.items()) {
      const size_t i = table_.size();
      table_.add({item.key(), [this, i](const FrameResult&, std::string& row) { row += fields_[i]; }});
    }
    fields_.resize(table_.size());
  }
  const CsvColumnTable& table() const { return table_; }
  // The record's fields, by column name; a key the first record did not have is left out.
  // `numbers`: the record's numbers as the message wrote them (RecordNumberTexts).
  void set(const Json& record, const std::map<std::string, std::string>& numbers) {
    for (size_t i = 0; i < table_.size(); ++i) {
      const std::string& name = table_.column(i).name;
      const auto it = record.find(name);
      const auto text = numbers.find(name);
      fields_[i] = it == record.end()
                       ? std::string()
                       : FieldText(*it, text != numbers.end() ? &text->second : nullptr);
    }
  }

 private:
  CsvColumnTable table_;
  std::vector<std::string> fields_;
};

void CheckHello(const ListenOptions& options, const Json& hello) {
  const auto version = hello.find("version");
  const auto format = hello.find("format");
  if (format == hello.end() || !format->is_string() || *format != kStreamFormatName ||
      version == hello.end() || !version->is_number_integer()) {
    throw InputError("listen " + options.endpoint + ": the publisher's hello is not " +
                     kStreamFormatName + "'s");
  }
  // As sent: a version beyond an int is not read modulo 2^32 (4294967297 is not 1).
  const bool same = version->is_number_unsigned()
                        ? version->get<uint64_t>() == static_cast<uint64_t>(kStreamFormatVersion)
                        : version->get<int64_t>() == kStreamFormatVersion;
  if (!same) {
    throw InputError("listen " + options.endpoint + ": the publisher speaks " + kStreamFormatName +
                     " version " + version->dump() + "; this softsight reads version " +
                     std::to_string(kStreamFormatVersion));
  }
  for (const char* key : {"source", "config", "config_digest"}) {
    const auto it = hello.find(key);
    if (it != hello.end() && !it->is_string()) {
      throw InputError("listen " + options.endpoint + ": the publisher's hello has " +
                       WithArticle(key) + " that is not text (" + it->dump().substr(0, 40) + ")");
    }
  }
  const auto columns = hello.find("columns");
  if (columns != hello.end() && !columns->is_array()) {
    throw InputError("listen " + options.endpoint + ": the publisher's hello has columns that are "
                     "not a list");
  }
}

// A record's field as softsight publishes them: a number, true/false, null, or a word (a status)
// without a CSV separator, quote or line break. Anything else would forge or shift rows of the
// CSV written from it: refused, naming the field.
void CheckRecordFields(const ListenOptions& options, const std::string& topic, const Json& record) {
  for (const auto& item : record.items()) {
    const Json& v = item.value();
    const bool plain_text =
        v.is_string() && v.get_ref<const std::string&>().find_first_of(",\"\r\n") == std::string::npos;
    if (!(v.is_number() || v.is_boolean() || v.is_null() || plain_text)) {
      throw InputError("listen " + options.endpoint + ": a '" + topic + "' record's field \"" +
                       item.key().substr(0, 40) + "\" is " +
                       (v.is_string() ? "text with a comma, quote or line break"
                                      : std::string("not a number or a word (") + v.type_name() + ")") +
                       ": not softsight's stream");
    }
  }
}

}  // namespace

std::string DescribeEndRecord(const std::string& body) {
  const Json end = Json::parse(body, nullptr, /*allow_exceptions=*/false);
  const auto number = [&end](const char* key) -> std::optional<int64_t> {
    const auto it = end.is_object() ? end.find(key) : end.end();
    if (it == end.end() || !it->is_number_integer()) return std::nullopt;
    return it->get<int64_t>();
  };
  const auto text = [&end](const char* key) -> std::optional<std::string> {
    const auto it = end.is_object() ? end.find(key) : end.end();
    if (it == end.end() || !it->is_string()) return std::nullopt;
    return it->get<std::string>();
  };
  const std::optional<int64_t> frames = number("frames"), sent = number("sent"),
                               dropped = number("dropped");
  const std::optional<std::string> reason = text("stop_reason"), error = text("error");
  if (!frames || !reason) return "the run ended: " + body;
  std::string line = "the run ended: " + std::to_string(*frames) + " frames (" + *reason + ")";
  if (sent) line += ", " + std::to_string(*sent) + " messages sent";
  if (dropped) line += ", " + std::to_string(*dropped) + " dropped";
  if (error && !error->empty()) line += "; error: " + *error;
  return line;
}

ListenSummary RunListen(const ListenOptions& options, std::ostream& out, std::ostream& err) {
  if (options.topic.empty() || options.topic.find(' ') != std::string::npos) {
    throw InputError("listen --topic '" + options.topic + "': give frame, measure or marker/NAME");
  }
  StreamSubscriber subscriber(options.endpoint, {kHelloTopic, options.topic, kEndTopic}, "listen");
  std::unique_ptr<RecordTable> records;
  std::unique_ptr<CsvWriter> csv;
  std::string row;
  std::map<std::string, std::string> numbers;  // Reused per record.
  std::optional<int64_t> last_frame;
  ListenSummary summary;
  auto heard = std::chrono::steady_clock::now();
  while (!(options.count && summary.records >= *options.count)) {
    if (options.stop_requested && options.stop_requested()) break;
    const std::optional<StreamMessage> message = subscriber.receive(kPollSliceMs);
    const auto now = std::chrono::steady_clock::now();
    if (!message) {
      if (options.timeout_s &&
          std::chrono::duration<double>(now - heard).count() > *options.timeout_s) {
        throw InputError("listen " + options.endpoint + ": nothing received for " +
                         ShortNumber(*options.timeout_s) + " s (--timeout-s); is the run started "
                         "with --publish at that endpoint?");
      }
      continue;
    }
    heard = now;
    const Json body = Json::parse(message->body, nullptr, /*allow_exceptions=*/false);
    if (body.is_discarded() || !body.is_object()) {
      throw InputError("listen " + options.endpoint + ": a '" + message->topic +
                       "' message is not a JSON object: \"" + message->body.substr(0, 60) + "\"");
    }
    if (message->topic == kHelloTopic) {
      CheckHello(options, body);
      if (summary.hellos++ == 0 && !options.quiet) {
        err << "listen: " << body.value("source", std::string()) << ", config "
            << body.value("config", std::string()) << " (digest "
            << body.value("config_digest", std::string()) << "), "
            << body.value("columns", Json::array()).size() << " columns, format version " << kStreamFormatVersion << "\n";
      }
      continue;
    }
    if (message->topic == kEndTopic) {
      summary.ended = true;
      summary.end_record = message->body;
      if (!options.quiet) err << "listen: " << DescribeEndRecord(message->body) << "\n";
      break;
    }
    if (message->topic != options.topic) continue;  // A longer topic with this prefix.
    if (summary.hellos == 0) {
      // Every run greets each new subscriber before its records: a record before any hello is
      // not from a softsight run (or from one this listener cannot check).
      ++summary.before_hello;
      continue;
    }
    CheckRecordFields(options, message->topic, body);
    ++summary.records;
    const auto frame = body.find("frame");
    if (frame != body.end() && frame->is_number_integer()) {
      const int64_t index = frame->get<int64_t>();
      if (last_frame && index > *last_frame + 1) summary.frame_gaps += index - *last_frame - 1;
      last_frame = index;
    }
    if (options.json) {
      out << message->body << "\n" << std::flush;
      continue;
    }
    if (!records) {
      records = std::make_unique<RecordTable>(body);
      if (!options.csv_file.empty()) {
        csv = std::make_unique<CsvWriter>(options.csv_file, records->table());
      } else {
        out << records->table().header() << "\n";
      }
    }
    RecordNumberTexts::Read(message->body, numbers);
    records->set(body, numbers);
    FrameResult named;  // Names the row in a write error.
    named.frame_index = last_frame.value_or(summary.records - 1);
    if (csv) {
      csv->write(named);
    } else {
      records->table().append_row(named, row);
      out << row << "\n" << std::flush;
    }
  }
  if (!options.quiet && summary.before_hello > 0) {
    err << "listen: " << summary.before_hello
        << " records before the publisher's hello were left out (not checked as softsight's)\n";
  }
  if (!options.quiet && summary.frame_gaps > 0) {
    err << "listen: " << summary.frame_gaps
        << " frame numbers missing between records (dropped for this listener, or by the source)\n";
  }
  return summary;
}

namespace {

const FlagTable<ListenOptions>& ListenFlags() {
  using A = ListenOptions;
  static const FlagTable<ListenOptions> table = {
      ValueFlag<A>("endpoint", &A::endpoint)
          .Help("Where the run publishes: tcp://HOST:PORT or ipc://PATH (its --publish, with * "
                "replaced by its host name)")
          .Required(),
      ValueFlag<A>("--topic", &A::topic)
          .Help("Which records: frame (every column), measure (the measurements), marker/NAME "
                "(one marker's columns)")
          .ShowDefault(),
      OutputFlag<A>(&A::csv_file, "csv", "Write the records to this CSV instead of printing them"),
      SwitchFlag<A>("--json", &A::json).Help("Print each record's JSON as it came, one per line"),
      ValueFlag<A>("--count", &A::count)
          .Help("Stop after this many records")
          .Check(NumberIn(1, 1e15)),
      ValueFlag<A>("--timeout-s", &A::timeout_s)
          .Help("Fail (exit 2) when nothing at all arrives for this many seconds (default: wait)")
          .Check(NumberIn(1e-3, 1e9)),
      SwitchFlag<A>(kQuietFlag, &A::quiet).Help("Nothing on stderr but errors"),
  };
  return table;
}

}  // namespace

CommandRunner SetupListenCommand(CLI::App& sub) {
  auto o = std::make_shared<ListenOptions>();
  sub.description(
      "Receive the results a run publishes (track, live, control or identify with --publish):\n"
      "print each frame's record as a CSV row, or write them to a CSV file, until the run ends.\n"
      "The records have the run's CSV columns and values (docs/stream.md).\n"
      "Examples:\n"
      "  softsight listen tcp://localhost:5556\n"
      "  softsight listen tcp://rig-pc:5556 --csv remote.csv\n"
      "  softsight listen ipc:///tmp/softsight.ipc --topic marker/green --json");
  AddFlags(sub, ListenFlags(), o.get());
  return [o] {
    const StopRequest stop;
    ListenOptions options = *o;
    options.stop_requested = [&stop] { return stop.requested(); };
    const ListenSummary summary = RunListen(options, std::cout, std::cerr);
    if (stop.requested() && !options.quiet) {
      std::cerr << "listen: " << StopSignalReason(stop.signal()) << " after " << summary.records
                << " records\n";
    }
    return ExitCodeAfterStop(0);
  };
}

}  // namespace softsight
