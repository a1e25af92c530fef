// The host build of the sketch: the .ino is C++ with Arduino's implicit #include <Arduino.h>.
#include <Arduino.h>

#include "../softsight_board/softsight_board.ino"
