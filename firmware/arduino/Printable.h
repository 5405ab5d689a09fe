/* Arduino's Printable: a class that knows how to print itself to a Print. */
#ifndef L6470EMU_PRINTABLE_H
#define L6470EMU_PRINTABLE_H

#include <stddef.h>

class Print;

class Printable {
 public:
  virtual ~Printable() = default;
  virtual size_t printTo(Print& p) const = 0;
};

#endif
