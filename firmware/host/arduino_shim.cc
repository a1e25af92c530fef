#include <deque>
#include <map>

#include "Arduino.h"
#include "shim_control.h"

namespace {

struct World {
  uint32_t micros = 0;
  std::map<uint8_t, int> analog_in;
  std::map<uint8_t, int> pwm;
  std::map<uint8_t, int> mode;
  unsigned long baud = 0;
  std::deque<char> rx;
  std::string tx;
};

World& TheWorld() {
  static World world;
  return world;
}

}  // namespace

HardwareSerial Serial;

void pinMode(uint8_t pin, uint8_t mode) { TheWorld().mode[pin] = mode; }
void digitalWrite(uint8_t pin, uint8_t value) { TheWorld().pwm[pin] = value ? 255 : 0; }
void analogWrite(uint8_t pin, int value) { TheWorld().pwm[pin] = value; }
int analogRead(uint8_t pin) {
  const auto it = TheWorld().analog_in.find(pin);
  return it == TheWorld().analog_in.end() ? 0 : it->second;
}
unsigned long millis() { return TheWorld().micros / 1000u; }
unsigned long micros() { return TheWorld().micros; }

void HardwareSerial::begin(unsigned long baud) { TheWorld().baud = baud; }
int HardwareSerial::available() { return static_cast<int>(TheWorld().rx.size()); }
int HardwareSerial::read() {
  if (TheWorld().rx.empty()) return -1;
  const char c = TheWorld().rx.front();
  TheWorld().rx.pop_front();
  return static_cast<unsigned char>(c);
}
size_t HardwareSerial::write(uint8_t c) {
  TheWorld().tx += static_cast<char>(c);
  return 1;
}
size_t HardwareSerial::write(const uint8_t* data, size_t n) {
  TheWorld().tx.append(reinterpret_cast<const char*>(data), n);
  return n;
}

namespace arduino_shim {

void Reset() { TheWorld() = World(); }
void SetMicros(uint32_t micros) { TheWorld().micros = micros; }
void SetAnalog(uint8_t pin, int counts) { TheWorld().analog_in[pin] = counts; }
int Pwm(uint8_t pin) {
  const auto it = TheWorld().pwm.find(pin);
  return it == TheWorld().pwm.end() ? -1 : it->second;
}
int Mode(uint8_t pin) {
  const auto it = TheWorld().mode.find(pin);
  return it == TheWorld().mode.end() ? -1 : it->second;
}
unsigned long Baud() { return TheWorld().baud; }
void SerialInput(const std::string& bytes) {
  for (char c : bytes) TheWorld().rx.push_back(c);
}
std::string TakeSerialOutput() {
  std::string out;
  out.swap(TheWorld().tx);
  return out;
}

}  // namespace arduino_shim
