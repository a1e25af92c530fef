// The test side of the Arduino shim: set the clock and the analog inputs, feed the serial port,
// read what the sketch wrote to its pins and its serial port.
#pragma once

#include <cstdint>
#include <string>

namespace arduino_shim {

void Reset();
void SetMicros(uint32_t micros);
void SetAnalog(uint8_t pin, int counts);
int Pwm(uint8_t pin);            // Last analogWrite value (-1 before any).
int Mode(uint8_t pin);           // Last pinMode (-1 before any).
unsigned long Baud();            // Serial.begin argument (0 before).
void SerialInput(const std::string& bytes);
std::string TakeSerialOutput();

}  // namespace arduino_shim
