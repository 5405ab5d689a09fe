/* Serial on the desktop: what the sketch writes goes to standard output (the CR of each CR LF
 * pair dropped, so println ends lines with a newline), and each call costs one HAL call of
 * virtual time (no baud rate is modelled). Serial reads the program's standard input (all of it
 * there from the start: it is read to its end at the first read) and the text of a scenario's
 * serial: steps from their tick on; available() is what has arrived. Serial1 and Serial2 write to
 * standard output too and read nothing. */
#ifndef L6470EMU_HARDWARE_SERIAL_H
#define L6470EMU_HARDWARE_SERIAL_H

#include "Stream.h"

#define SERIAL_5N1 0x00
#define SERIAL_6N1 0x02
#define SERIAL_7N1 0x04
#define SERIAL_8N1 0x06
#define SERIAL_8N2 0x0E
#define SERIAL_8E1 0x26
#define SERIAL_8O1 0x36

class HardwareSerial : public Stream {
 public:
  void begin(unsigned long baud, uint32_t config = SERIAL_8N1, int8_t rx_pin = -1, int8_t tx_pin = -1,
             bool invert = false, unsigned long timeout_ms = 20000UL);
  void end();
  int available() override;
  int peek() override;
  int read() override;
  int availableForWrite() override;
  void flush() override;
  size_t write(uint8_t c) override;
  size_t write(const uint8_t* buffer, size_t size) override;
  using Print::write;
  /* while (!Serial) waits for a USB host on some boards; here one is always there. */
  explicit operator bool();
};

extern HardwareSerial Serial;
extern HardwareSerial Serial1;
extern HardwareSerial Serial2;

#endif
