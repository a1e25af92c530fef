// A small stand-in for the Arduino core, so the sketch compiles and runs on the host (CI builds it
// and firmware_test.cc drives it). Only what the sketch uses; plain C headers, like the real core.
// The test side controls it through shim_control.h.
#pragma once

#include <stddef.h>
#include <stdint.h>

#define INPUT 0x0
#define OUTPUT 0x1
#define LOW 0x0
#define HIGH 0x1

const uint8_t A0 = 14;

void pinMode(uint8_t pin, uint8_t mode);
void digitalWrite(uint8_t pin, uint8_t value);
void analogWrite(uint8_t pin, int value);
int analogRead(uint8_t pin);
unsigned long millis();
unsigned long micros();

class HardwareSerial {
 public:
  void begin(unsigned long baud);
  int available();
  int read();
  size_t write(uint8_t c);
  size_t write(const uint8_t* data, size_t n);
};

extern HardwareSerial Serial;

// Provided by the sketch.
void setup();
void loop();
