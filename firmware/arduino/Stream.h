/* Arduino's Stream: a Print that can also be read, with timed reads in virtual time. */
#ifndef L6470EMU_STREAM_H
#define L6470EMU_STREAM_H

#include "Print.h"

class Stream : public Print {
 public:
  virtual int available() = 0;
  virtual int read() = 0;
  virtual int peek() = 0;

  void setTimeout(unsigned long timeout_ms) { timeout_ms_ = timeout_ms; }
  unsigned long getTimeout() const { return timeout_ms_; }
  /* These wait up to the timeout (1000 ms) of virtual time for input that is not there yet. */
  size_t readBytes(char* buffer, size_t length);
  size_t readBytes(uint8_t* buffer, size_t length) { return readBytes(reinterpret_cast<char*>(buffer), length); }
  size_t readBytesUntil(char terminator, char* buffer, size_t length);
  String readString();
  String readStringUntil(char terminator);
  long parseInt();
  float parseFloat();
  bool find(const char* target);

 protected:
  int timedRead();
  int timedPeek();

 private:
  unsigned long timeout_ms_ = 1000;
};

#endif
