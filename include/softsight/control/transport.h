// The seam between the controller and the wire: a line-oriented transport. The real serial port
// (LibSerial) and a pseudo-terminal's master side (the simulated rig, tests) sit behind it, so the
// controller is tested against a simulated board exactly as it drives a real one.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace softsight {

class Transport {
 public:
  virtual ~Transport() = default;
  // Writes `line` (which should end in '\n'). Throws InputError naming the port when the port
  // fails or has disappeared.
  virtual void write_line(std::string_view line) = 0;
  // The next complete line, without '\n', or nothing when no full line arrived within
  // `timeout_ms`. Lines longer than 512 bytes come back truncated to 512 (the decoder rejects
  // them). Throws InputError naming the port when the port fails or has disappeared.
  virtual std::optional<std::string> read_line(int timeout_ms) = 0;
  // "serial port /dev/ttyACM0", for messages.
  virtual const std::string& name() const = 0;
};

// Opens a serial device (e.g. /dev/ttyACM0, or a pseudo-terminal's /dev/pts/N) through LibSerial:
// raw 8N1, no flow control, at `baud` (one of 9600, 19200, 38400, 57600, 115200, 230400).
// Throws InputError naming the port when it cannot be opened.
std::unique_ptr<Transport> OpenSerialTransport(const std::string& port, int baud);

// A transport over an already open file descriptor (a pty master, one end of a socketpair).
// Takes ownership of `fd`.
std::unique_ptr<Transport> MakeFdTransport(int fd, std::string name);

// A pseudo-terminal pair in raw mode. The slave path behaves as a serial device for whoever opens
// it; the master is the other end of the wire. The slave stays open here too, so the master does
// not see a hang-up when the host closes and re-opens the port.
class PseudoTerminal {
 public:
  // Throws InputError when the system has no free pseudo-terminal.
  PseudoTerminal();
  ~PseudoTerminal();
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  int master_fd() const { return master_fd_; }
  const std::string& slave_path() const { return slave_path_; }
  // Closes both ends: whoever has the slave open sees the port disappear (EIO / hang-up).
  void close();

 private:
  int master_fd_ = -1;
  int slave_fd_ = -1;
  std::string slave_path_;
};

}  // namespace softsight
