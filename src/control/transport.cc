#include "softsight/control/transport.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <vector>

#include <libserial/SerialPort.h>

#include "softsight/core/error.h"

namespace softsight {
namespace {

constexpr size_t kMaxHostLine = 512;

// Splits bytes read from a descriptor into lines, with a wall-clock timeout. Shared by the
// LibSerial transport (through its descriptor) and the plain fd transport.
class LineReader {
 public:
  // Returns a line, nothing on timeout; throws InputError("<name>: ...") on failure/hang-up.
  std::optional<std::string> read_line(int fd, int timeout_ms, const std::string& name) {
    if (auto line = take_line()) return line;
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (true) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      pollfd p{fd, POLLIN, 0};
      const int ready = ::poll(&p, 1, static_cast<int>(std::max<int64_t>(0, left.count())));
      if (ready < 0) {
        if (errno == EINTR) continue;
        throw InputError(name + ": poll failed (" + std::strerror(errno) + ")");
      }
      if (ready == 0) return std::nullopt;
      if ((p.revents & (POLLIN | POLLHUP | POLLERR | POLLNVAL)) == 0) continue;
      char chunk[256];
      const ssize_t n = ::read(fd, chunk, sizeof(chunk));
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n <= 0) {
        throw InputError(name + ": device disconnected (" +
                         (n == 0 ? std::string("end of file") : std::strerror(errno)) +
                         "); check the cable or whether the rig is still running");
      }
      append(chunk, static_cast<size_t>(n));
      if (auto line = take_line()) return line;
    }
  }

 private:
  void append(const char* data, size_t n) {
    for (size_t i = 0; i < n; ++i) {
      const char c = data[i];
      if (c == '\n') {
        lines_ready_.push_back(std::move(current_));
        current_.clear();
      } else if (current_.size() < kMaxHostLine) {
        current_ += c;
      }
    }
  }
  std::optional<std::string> take_line() {
    if (next_ >= lines_ready_.size()) {
      lines_ready_.clear();
      next_ = 0;
      return std::nullopt;
    }
    return std::move(lines_ready_[next_++]);
  }

  std::string current_;
  std::vector<std::string> lines_ready_;
  size_t next_ = 0;
};

void WriteAll(int fd, std::string_view data, const std::string& name) {
  size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EAGAIN) {
      pollfd p{fd, POLLOUT, 0};
      ::poll(&p, 1, 100);
      continue;
    }
    if (n <= 0) {
      throw InputError(name + ": write failed, device disconnected (" + std::strerror(errno) +
                       "); check the cable or whether the rig is still running");
    }
    done += static_cast<size_t>(n);
  }
}

class FdTransport : public Transport {
 public:
  FdTransport(int fd, std::string name) : fd_(fd), name_(std::move(name)) {}
  ~FdTransport() override {
    if (fd_ >= 0) ::close(fd_);
  }
  void write_line(std::string_view line) override { WriteAll(fd_, line, name_); }
  std::optional<std::string> read_line(int timeout_ms) override {
    return reader_.read_line(fd_, timeout_ms, name_);
  }
  const std::string& name() const override { return name_; }

 private:
  int fd_;
  std::string name_;
  LineReader reader_;
};

LibSerial::BaudRate ToBaudRate(int baud, const std::string& port) {
  switch (baud) {
    case 9600: return LibSerial::BaudRate::BAUD_9600;
    case 19200: return LibSerial::BaudRate::BAUD_19200;
    case 38400: return LibSerial::BaudRate::BAUD_38400;
    case 57600: return LibSerial::BaudRate::BAUD_57600;
    case 115200: return LibSerial::BaudRate::BAUD_115200;
    case 230400: return LibSerial::BaudRate::BAUD_230400;
    default:
      throw InputError("serial port " + port + ": unsupported baud rate " + std::to_string(baud) +
                       " (use 9600, 19200, 38400, 57600, 115200 or 230400)");
  }
}

// LibSerial opens and configures the device; reads go through its descriptor with poll() so a
// timeout never loses a partial line (LibSerial's ReadLine drops it).
class SerialTransport : public Transport {
 public:
  SerialTransport(const std::string& port, int baud) : name_("serial port " + port) {
    const LibSerial::BaudRate rate = ToBaudRate(baud, port);
    // LibSerial reports a missing device as "Bad file descriptor": say what is wrong instead.
    if (::access(port.c_str(), F_OK) != 0) {
      throw InputError(name_ + ": cannot open (" + std::strerror(errno) +
                       "); is the board plugged in? try `ls /dev/ttyACM* /dev/ttyUSB*`");
    }
    RefuseWhatIsNotATerminal(port);
    try {
      port_->Open(port);
    } catch (const std::exception& e) {
      throw InputError(name_ + ": cannot open (" + e.what() +
                       "); check the device path and that you may access it (group dialout)");
    }
    // A second host on the same port would reset the board under the first one's loop; the lock
    // is advisory but every softsight process takes it, and it goes with the descriptor.
    if (::flock(port_->GetFileDescriptor(), LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      ClosePort();
      throw InputError(name_ + ": " +
                       (error == EWOULDBLOCK ? std::string("in use by another softsight process")
                                             : std::string("cannot lock (") +
                                                   std::strerror(error) + ")") +
                       "; one host per board");
    }
    try {
      port_->SetBaudRate(rate);
      port_->SetCharacterSize(LibSerial::CharacterSize::CHAR_SIZE_8);
      port_->SetParity(LibSerial::Parity::PARITY_NONE);
      port_->SetStopBits(LibSerial::StopBits::STOP_BITS_1);
      port_->SetFlowControl(LibSerial::FlowControl::FLOW_CONTROL_NONE);
    } catch (const std::exception& e) {
      // Closed here: LibSerial's destructor would throw again while the exception is in flight.
      ClosePort();
      throw InputError(name_ + ": cannot set up the port (" + e.what() +
                       "); is it a serial device?");
    }
  }
  ~SerialTransport() override { ClosePort(); }
  void write_line(std::string_view line) override {
    WriteAll(port_->GetFileDescriptor(), line, name_);
  }
  std::optional<std::string> read_line(int timeout_ms) override {
    return reader_.read_line(port_->GetFileDescriptor(), timeout_ms, name_);
  }
  const std::string& name() const override { return name_; }

 private:
  // LibSerial only finds out that a path is no terminal after opening it, and then throws from its
  // destructor: check first, with the kind of file named.
  void RefuseWhatIsNotATerminal(const std::string& port) const {
    const int fd = ::open(port.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
      throw InputError(name_ + ": cannot open (" + std::strerror(errno) +
                       "); check the device path and that you may access it (group dialout)");
    }
    struct stat st {};
    const bool stat_ok = ::fstat(fd, &st) == 0;
    const bool terminal = ::isatty(fd) == 1;
    ::close(fd);
    if (stat_ok && !S_ISCHR(st.st_mode)) {
      const char* kind = S_ISREG(st.st_mode)    ? "a regular file"
                         : S_ISFIFO(st.st_mode) ? "a FIFO"
                         : S_ISDIR(st.st_mode)  ? "a folder"
                         : S_ISSOCK(st.st_mode) ? "a socket"
                                                : "not a character device";
      throw InputError(name_ + ": " + kind + ", not a serial device; the board is usually " +
                       "/dev/ttyACM0 or /dev/ttyUSB0");
    }
    if (!terminal) {
      throw InputError(name_ + ": a device that is not a terminal (e.g. /dev/null), not a " +
                       "serial port; the board is usually /dev/ttyACM0 or /dev/ttyUSB0");
    }
  }

  void ClosePort() {
    if (!port_) return;
    try {
      if (port_->IsOpen()) port_->Close();
      return;
    } catch (const std::exception&) {
      // The device has disappeared: LibSerial's Close fails restoring the old settings before it
      // closes the descriptor, and its destructor would try again and throw (terminate).
    }
    // Put a live terminal under the same descriptor number so that Close succeeds and releases
    // everything; if even that fails, close the descriptor and leave the small object behind.
    int fd = -1;
    int master = -1;
    try {
      fd = port_->GetFileDescriptor();
      int slave = -1;
      if (::openpty(&master, &slave, nullptr, nullptr, nullptr) == 0) {
        ::dup2(slave, fd);
        ::close(slave);
        port_->Close();
        ::close(master);
        return;
      }
    } catch (const std::exception&) {
      // Fall through.
    }
    if (master >= 0) ::close(master);
    if (fd >= 0) ::close(fd);
    (void)port_.release();
  }

  std::unique_ptr<LibSerial::SerialPort> port_ = std::make_unique<LibSerial::SerialPort>();
  std::string name_;
  LineReader reader_;
};

}  // namespace

std::unique_ptr<Transport> OpenSerialTransport(const std::string& port, int baud) {
  return std::make_unique<SerialTransport>(port, baud);
}

std::unique_ptr<Transport> MakeFdTransport(int fd, std::string name) {
  return std::make_unique<FdTransport>(fd, std::move(name));
}

PseudoTerminal::PseudoTerminal() {
  termios raw{};
  cfmakeraw(&raw);
  cfsetispeed(&raw, B115200);
  cfsetospeed(&raw, B115200);
  char name[256] = {0};
  if (::openpty(&master_fd_, &slave_fd_, name, &raw, nullptr) != 0) {
    throw InputError(std::string("pseudo-terminal: cannot open one (") + std::strerror(errno) +
                     ")");
  }
  ::fcntl(master_fd_, F_SETFD, FD_CLOEXEC);
  ::fcntl(slave_fd_, F_SETFD, FD_CLOEXEC);
  slave_path_ = name;
}

PseudoTerminal::~PseudoTerminal() { close(); }

void PseudoTerminal::close() {
  if (master_fd_ >= 0) ::close(master_fd_);
  if (slave_fd_ >= 0) ::close(slave_fd_);
  master_fd_ = slave_fd_ = -1;
}

}  // namespace softsight
