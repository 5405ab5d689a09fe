/* Arduino's SPI library on the desktop: an SPIClass is one SPI controller of the emulated board
 * (docs/firmware.md, "The pin map"); its bytes reach every chain whose chip select the sketch has
 * driven low with digitalWrite, each byte taking its bus time at the transaction's clock, and
 * the mode and bit order go to the board as the sketch set them. The AVR, ESP32 (SPIClass(HSPI),
 * transferBytes) and STM32duino (SPIClass(mosi, miso, sclk), transfer(tx, rx, n)) variants are
 * here; hardware chip selects and DMA are not. */
#ifndef L6470EMU_SPI_H
#define L6470EMU_SPI_H

#include "Arduino.h"

#define SPI_HAS_TRANSACTION 1
#define SPI_HAS_NOTUSINGINTERRUPT 1
#define SPI_ATOMIC_VERSION 1

/* The AVR core's values; 0 to 3 are taken as the mode number too. */
#define SPI_MODE0 0x00
#define SPI_MODE1 0x04
#define SPI_MODE2 0x08
#define SPI_MODE3 0x0C

/* Dividers of F_CPU = 16 MHz (AVR values). */
#define SPI_CLOCK_DIV4 0x00
#define SPI_CLOCK_DIV16 0x01
#define SPI_CLOCK_DIV64 0x02
#define SPI_CLOCK_DIV128 0x03
#define SPI_CLOCK_DIV2 0x04
#define SPI_CLOCK_DIV8 0x05
#define SPI_CLOCK_DIV32 0x06

/* ESP32 controller numbers (SPIClass(HSPI)); the global SPI is the one called "SPI". */
#define FSPI 1
#define HSPI 2
#define VSPI 3

typedef int SPIMode;

class SPISettings {
 public:
  SPISettings() : clock_(4000000), bit_order_(MSBFIRST), data_mode_(SPI_MODE0) {}
  SPISettings(uint32_t clock, uint8_t bitOrder, uint8_t dataMode)
      : clock_(clock), bit_order_(bitOrder), data_mode_(dataMode) {}
  uint32_t getClockFreq() const { return clock_; }
  uint8_t getBitOrder() const { return bit_order_; }
  uint8_t getDataMode() const { return data_mode_; }

 private:
  friend class SPIClass;
  uint32_t clock_;
  uint8_t bit_order_;
  uint8_t data_mode_;
};

class SPIClass {
 public:
  /* The controller called "SPI". */
  SPIClass();
  /* ESP32: FSPI, HSPI or VSPI. */
  explicit SPIClass(uint8_t spi_bus);
  /* STM32duino: the controller whose default MOSI pin `mosi` is on an STM32F4 (PA7, PB5: SPI1;
   * PB15, PC3: SPI2; PC12: SPI3; PE6, PE14: SPI4), else "SPI". */
  SPIClass(uint32_t mosi, uint32_t miso, uint32_t sclk, uint32_t ssel = 0xFFFFFFFFu);

  /* Pins are the board description's business: begin's arguments are accepted and ignored. */
  void begin(int8_t sck = -1, int8_t miso = -1, int8_t mosi = -1, int8_t ss = -1);
  void end();

  void beginTransaction(SPISettings settings);
  void endTransaction(void);

  uint8_t transfer(uint8_t data);
  uint16_t transfer16(uint16_t data);
  uint32_t transfer32(uint32_t data);
  void transfer(void* buf, size_t count);
  void transfer(const void* tx_buf, void* rx_buf, size_t count);
  void transferBytes(const uint8_t* data, uint8_t* out, uint32_t size);
  void write(uint8_t data);
  void write16(uint16_t data);
  void write32(uint32_t data);
  void writeBytes(const uint8_t* data, uint32_t size);

  /* Outside a transaction (the pre-1.6 API). */
  void setBitOrder(uint8_t bitOrder);
  void setDataMode(uint8_t dataMode);
  void setClockDivider(uint8_t clockDiv);
  void setFrequency(uint32_t freq);

  /* An interrupt that uses SPI is held off between beginTransaction and endTransaction. */
  void usingInterrupt(int interruptNumber);
  void notUsingInterrupt(int interruptNumber);
  void attachInterrupt() {}
  void detachInterrupt() {}

  /* STM32duino's pin setters: accepted and ignored. */
  void setMOSI(uint32_t) {}
  void setMISO(uint32_t) {}
  void setSCLK(uint32_t) {}
  void setSSEL(uint32_t) {}

  /* The controller's name ("SPI", "HSPI", "SPI2"): what the board description's spi= says. */
  const char* name() const { return name_; }

 private:
  void bytes(const uint8_t* tx, uint8_t* rx, size_t count);
  const char* name_;
  SPISettings settings_;
  int controller_ = -2;  // -2: not looked up yet
  bool in_transaction_ = false;
  bool begun_ = false;
  int masked_[4] = {-1, -1, -1, -1};
};

extern SPIClass SPI;
/* The second and third controllers of cores that have them (Teensy, Due, STM32duino boards). */
extern SPIClass SPI1;
extern SPIClass SPI2;

#endif
