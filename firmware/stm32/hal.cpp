// The STM32Cube HAL subset over the FirmwareRuntime: GPIO ports and pins as the description's
// PXn pins, EXTI lines as interrupts grouped into their NVIC vectors, SPI handles as
// controllers with the settings of their Init, HAL_Delay and HAL_GetTick in virtual time.
// The model first: stm32_hal.h's macros (RESET, SET, ERROR, SPI1, ...) must not reach its headers.
#include "firmware/runtime.hpp"
#include "firmware/stm32/hal_internal.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <vector>

#include "stm32_hal.h"

using l6470emu::FirmwareFront;
using l6470emu::FirmwareRuntime;
using l6470emu::Tick;

GPIO_TypeDef l6470emu_gpio_ports[11] = {{0}, {1}, {2}, {3}, {4}, {5}, {6}, {7}, {8}, {9}, {10}};
SPI_TypeDef l6470emu_spi_instances[6] = {{0}, {1}, {2}, {3}, {4}, {5}};
uint32_t SystemCoreClock = 168000000U;

namespace {

// The NVIC vectors the EXTI lines raise (F1/F4/L4 style; F0/G0/L0 group them in threes).
enum Vector { kExti0, kExti1, kExti2, kExti3, kExti4, kExti9_5, kExti15_10, kExti0_1, kExti2_3, kExti4_15, kVectors };

struct Hal {
  FirmwareRuntime* rt = nullptr;
  std::array<int, kVectors> irq{};           // the runtime interrupt of each vector
  std::array<bool, kVectors> enabled{};      // HAL_NVIC_EnableIRQ
  std::uint32_t pending = 0;                 // EXTI pending lines (PR)
  std::array<int, 16> line_key{};            // the pin each EXTI line watches (-1: none)
  std::array<bool, 16> rose{};               // the direction of each line's last edge
};
Hal g;

void run_vector(int v);

FirmwareRuntime& rt() {
  if (!g.rt) {
    g.rt = &l6470emu::firmware_runtime(FirmwareFront::stm32_hal);
    g.line_key.fill(-1);
    for (int v = 0; v < kVectors; ++v) {
      g.irq[static_cast<std::size_t>(v)] = g.rt->add_irq([v] { run_vector(v); });
      g.rt->set_irq_enabled(g.irq[static_cast<std::size_t>(v)], false);  // until HAL_NVIC_EnableIRQ
    }
  }
  return *g.rt;
}

// Each HAL call: its cost, then what is pending.
FirmwareRuntime& call() {
  FirmwareRuntime& r = rt();
  r.call();
  return r;
}

int key(const GPIO_TypeDef* port, unsigned pin) {
  return 128 + static_cast<int>(port->l6470emu_port) * 16 + static_cast<int>(pin);
}

bool valid_port(const GPIO_TypeDef* port) {
  return port >= l6470emu_gpio_ports && port < l6470emu_gpio_ports + 11;
}

std::vector<int> vectors_of_line(unsigned line) {
  std::vector<int> v;
  v.push_back(line <= 4 ? static_cast<int>(line) : line <= 9 ? kExti9_5 : kExti15_10);
  v.push_back(line <= 1 ? kExti0_1 : line <= 3 ? kExti2_3 : kExti4_15);
  return v;
}

int vector_of_irqn(IRQn_Type irqn) {
  switch (irqn) {
    case EXTI0_IRQn: return kExti0;
    case EXTI1_IRQn: return kExti1;
    case EXTI2_IRQn: return kExti2;
    case EXTI3_IRQn: return kExti3;
    case EXTI4_IRQn: return kExti4;
    case EXTI9_5_IRQn: return kExti9_5;
    case EXTI15_10_IRQn: return kExti15_10;
    case EXTI0_1_IRQn: return kExti0_1;
    case EXTI2_3_IRQn: return kExti2_3;
    case EXTI4_15_IRQn: return kExti4_15;
    default: return -1;
  }
}

std::uint32_t lines_of_vector(int v) {
  switch (v) {
    case kExti9_5: return 0x03E0;
    case kExti15_10: return 0xFC00;
    case kExti0_1: return 0x0003;
    case kExti2_3: return 0x000C;
    case kExti4_15: return 0xFFF0;
    default: return 1u << v;
  }
}

void pend_line(unsigned line, bool level) {
  g.pending |= 1u << line;
  g.rose[line] = level;
  for (const int v : vectors_of_line(line))
    if (g.enabled[static_cast<std::size_t>(v)]) g.rt->pend_irq(g.irq[static_cast<std::size_t>(v)]);
}

void run_vector(int v) {
  switch (v) {
    case kExti0: EXTI0_IRQHandler(); break;
    case kExti1: EXTI1_IRQHandler(); break;
    case kExti2: EXTI2_IRQHandler(); break;
    case kExti3: EXTI3_IRQHandler(); break;
    case kExti4: EXTI4_IRQHandler(); break;
    case kExti9_5: EXTI9_5_IRQHandler(); break;
    case kExti15_10: EXTI15_10_IRQHandler(); break;
    case kExti0_1: EXTI0_1_IRQHandler(); break;
    case kExti2_3: EXTI2_3_IRQHandler(); break;
    case kExti4_15: EXTI4_15_IRQHandler(); break;
    default: break;
  }
  // A line the handler left pending raises its vector again (at the next call, not at once).
  if (g.pending & lines_of_vector(v)) g.rt->pend_irq(g.irq[static_cast<std::size_t>(v)]);
}

void handle_lines(std::uint32_t lines) {
  for (unsigned line = 0; line < 16; ++line)
    if (lines & (1u << line)) HAL_GPIO_EXTI_IRQHandler(static_cast<uint16_t>(1u << line));
}

// ---- SPI

struct SpiSettings {
  l6470emu::BusSettings bus;
  bool sixteen = false;
};

SpiSettings settings_of(const SPI_HandleTypeDef* h) {
  SpiSettings s;
  const std::uint32_t apb = rt().timing().apb_clock_hz;
  const unsigned shift = 1 + ((h->Init.BaudRatePrescaler >> 3) & 7);  // /2 ... /256
  s.bus.speed_hz = std::max<std::uint32_t>(1, apb >> shift);
  s.bus.mode = static_cast<std::uint8_t>((h->Init.CLKPolarity == SPI_POLARITY_HIGH ? 2 : 0) +
                                         (h->Init.CLKPhase == SPI_PHASE_2EDGE ? 1 : 0));
  s.bus.lsb_first = h->Init.FirstBit == SPI_FIRSTBIT_LSB;
  s.sixteen = h->Init.DataSize == SPI_DATASIZE_16BIT || h->Init.DataSize == 0x00000800U;  // F1/F4 write DFF as 0x800
  s.bus.bits_per_word = s.sixteen ? 16 : 8;
  return s;
}

HAL_StatusTypeDef spi_transfer(SPI_HandleTypeDef* h, const uint8_t* tx, uint8_t* rx, uint16_t size, uint32_t timeout,
                               bool has_timeout) {
  FirmwareRuntime& r = call();
  if (!h || !h->Instance) return HAL_ERROR;
  if (h->State != HAL_SPI_STATE_READY) {
    r.log("HAL_SPI: a transfer on a handle that is not ready (HAL_SPI_Init not called, or busy): HAL_BUSY, "
          "as on the MCU");
    return HAL_BUSY;
  }
  if (size == 0 || (!tx && !rx)) return HAL_ERROR;
  const auto index = static_cast<std::size_t>(h->Instance - l6470emu_spi_instances);
  if (index >= 6) return HAL_ERROR;
  const int controller = r.controller("SPI" + std::to_string(index + 1));
  const SpiSettings s = settings_of(h);
  const std::size_t word = s.sixteen ? 2 : 1;
  const std::size_t n = size * word;
  // The bytes in wire order: a 16-bit word's high byte first MSB first, low byte first LSB first.
  std::vector<std::uint8_t> out(n, 0), in(n, 0);
  for (std::size_t w = 0; w < size; ++w) {
    if (!tx) break;
    if (word == 1) {
      out[w] = tx[w];
    } else {
      std::uint16_t v;
      std::memcpy(&v, tx + 2 * w, 2);
      out[2 * w] = static_cast<std::uint8_t>(s.bus.lsb_first ? v : v >> 8);
      out[2 * w + 1] = static_cast<std::uint8_t>(s.bus.lsb_first ? v >> 8 : v);
    }
  }
  h->State = HAL_SPI_STATE_BUSY_TX_RX;
  h->ErrorCode = HAL_SPI_ERROR_NONE;
  const Tick start_ms = r.now() / l6470emu::ticks_from_ms(1);
  const Tick per_word = l6470emu::transfer_ticks(static_cast<std::uint32_t>(word), s.bus.speed_hz);
  std::size_t done = size;
  HAL_StatusTypeDef status = HAL_OK;
  if (has_timeout && timeout != HAL_MAX_DELAY) {
    // ST's loop gives up once HAL_GetTick() has moved Timeout on: words until then are sent.
    const Tick deadline = (start_ms + timeout) * l6470emu::ticks_from_ms(1);
    const Tick fit = timeout == 0 ? 1 : (deadline > r.now() ? (deadline - r.now() + per_word - 1) / per_word : 1);
    if (fit < size) {
      done = static_cast<std::size_t>(std::max<Tick>(1, fit));
      status = HAL_TIMEOUT;
    }
  }
  if (controller >= 0) {
    r.transfer(controller, s.bus, std::span<const std::uint8_t>(out.data(), done * word),
               std::span<std::uint8_t>(in.data(), done * word));
  } else {
    r.log("HAL_SPI: SPI" + std::to_string(index + 1) + " is not on the board: its words reach no chip");
    r.spend(per_word * done);
  }
  if (rx) {
    for (std::size_t w = 0; w < done; ++w) {
      if (word == 1) {
        rx[w] = in[w];
      } else {
        const std::uint16_t v = s.bus.lsb_first ? static_cast<std::uint16_t>(in[2 * w + 1] << 8 | in[2 * w])
                                                : static_cast<std::uint16_t>(in[2 * w] << 8 | in[2 * w + 1]);
        std::memcpy(rx + 2 * w, &v, 2);
      }
    }
  }
  h->State = HAL_SPI_STATE_READY;
  if (status == HAL_TIMEOUT) h->ErrorCode = HAL_SPI_ERROR_FLAG;
  return status;
}

}  // namespace

extern "C" {

// ---------------------------------------------------------------- core

void __disable_irq(void) { call().disable_interrupts(); }
void __enable_irq(void) { call().enable_interrupts(); }
uint32_t __get_PRIMASK(void) { return rt().interrupts_enabled() ? 0U : 1U; }
void __set_PRIMASK(uint32_t priMask) {
  FirmwareRuntime& r = call();
  priMask ? r.disable_interrupts() : r.enable_interrupts();
}
void SystemInit(void) {}
void SystemCoreClockUpdate(void) {}

__weak void HAL_MspInit(void) {}
__weak void HAL_MspDeInit(void) {}

HAL_StatusTypeDef HAL_Init(void) {
  call();
  HAL_InitTick(0);
  HAL_MspInit();
  return HAL_OK;
}

HAL_StatusTypeDef HAL_DeInit(void) {
  call();
  HAL_MspDeInit();
  return HAL_OK;
}

__weak HAL_StatusTypeDef HAL_InitTick(uint32_t) { return HAL_OK; }

__weak uint32_t HAL_GetTick(void) {
  FirmwareRuntime& r = call();
  return l6470emu::board_millis(r.now());  // wraps at 2^32 ms as the SysTick counter does
}

uint32_t HAL_GetTickPrio(void) { return 0; }
HAL_TickFreqTypeDef HAL_GetTickFreq(void) { return HAL_TICK_FREQ_1KHZ; }
HAL_StatusTypeDef HAL_SetTickFreq(HAL_TickFreqTypeDef) { return HAL_OK; }
__weak void HAL_IncTick(void) {}

__weak void HAL_Delay(uint32_t Delay) {
  FirmwareRuntime& r = call();
  const Tick ms = l6470emu::ticks_from_ms(1);
  const Tick tickstart = r.now() / ms;
  if (Delay == HAL_MAX_DELAY) r.sleep_until(l6470emu::kNever);  // ends the run at its limit
  r.sleep_until((tickstart + Delay + 1) * ms);  // ST waits one tick more, so at least Delay ms pass
}

void HAL_SuspendTick(void) {}
void HAL_ResumeTick(void) {}
uint32_t HAL_GetHalVersion(void) { return 0x01080000U; }
uint32_t HAL_GetDEVID(void) { return 0x413U; }
uint32_t HAL_GetREVID(void) { return 0x1000U; }

// ---------------------------------------------------------------- GPIO

void HAL_GPIO_Init(GPIO_TypeDef* GPIOx, GPIO_InitTypeDef* init) {
  FirmwareRuntime& r = call();
  if (!valid_port(GPIOx) || !init) return;
  for (unsigned pin = 0; pin < 16; ++pin) {
    if (!(init->Pin & (1u << pin))) continue;
    const int k = key(GPIOx, pin);
    const std::uint32_t mode = init->Mode;
    l6470emu::McuPinMode m = l6470emu::McuPinMode::input;
    if (mode == GPIO_MODE_OUTPUT_PP) m = l6470emu::McuPinMode::output;
    if (mode == GPIO_MODE_OUTPUT_OD) m = l6470emu::McuPinMode::output_open_drain;
    const bool input = m == l6470emu::McuPinMode::input;
    if (input && init->Pull == GPIO_PULLUP) m = l6470emu::McuPinMode::input_pullup;
    if (input && init->Pull == GPIO_PULLDOWN) m = l6470emu::McuPinMode::input_pulldown;
    const bool af = mode == GPIO_MODE_AF_PP || mode == GPIO_MODE_AF_OD;
    const bool timer_output = l6470emu_tim_gpio_af(GPIOx->l6470emu_port * 16 + pin, af ? init->Alternate : ~0u);
    if (af && !timer_output && r.pin_wired(k))
      r.log("HAL_GPIO_Init: pin " + l6470emu::to_string(FirmwareRuntime::pin_of(k)) +
            " given to a peripheral (alternate function) but the board wires it to a chip: a hardware chip "
            "select is not modelled; drive CS with HAL_GPIO_WritePin");
    r.set_pin_mode(k, m);
    // An EXTI line: the pin becomes its source (as SYSCFG's EXTICR selects the port).
    const bool it = (mode & 0x10000000U) && (mode & 0x00010000U);
    if (g.line_key[pin] >= 0 && (g.line_key[pin] != k || !it)) {
      r.watch_pin(g.line_key[pin], 0, nullptr);
      g.line_key[pin] = -1;
    }
    if (it) {
      const unsigned edges = ((mode & 0x00100000U) ? l6470emu::kEdgeRising : 0u) |
                             ((mode & 0x00200000U) ? l6470emu::kEdgeFalling : 0u);
      g.line_key[pin] = k;
      r.watch_pin(k, edges, [pin](bool level) { pend_line(pin, level); });
    }
  }
}

void HAL_GPIO_DeInit(GPIO_TypeDef* GPIOx, uint32_t GPIO_Pin) {
  FirmwareRuntime& r = call();
  if (!valid_port(GPIOx)) return;
  for (unsigned pin = 0; pin < 16; ++pin) {
    if (!(GPIO_Pin & (1u << pin))) continue;
    const int k = key(GPIOx, pin);
    if (g.line_key[pin] == k) {
      r.watch_pin(k, 0, nullptr);
      g.line_key[pin] = -1;
    }
    r.set_pin_mode(k, l6470emu::McuPinMode::input);
  }
}

GPIO_PinState HAL_GPIO_ReadPin(GPIO_TypeDef* GPIOx, uint16_t GPIO_Pin) {
  FirmwareRuntime& r = call();
  if (!valid_port(GPIOx)) return GPIO_PIN_RESET;
  for (unsigned pin = 0; pin < 16; ++pin)
    if ((GPIO_Pin & (1u << pin)) && r.read_pin(key(GPIOx, pin))) return GPIO_PIN_SET;
  return GPIO_PIN_RESET;
}

void HAL_GPIO_WritePin(GPIO_TypeDef* GPIOx, uint16_t GPIO_Pin, GPIO_PinState PinState) {
  FirmwareRuntime& r = call();
  if (!valid_port(GPIOx)) return;
  for (unsigned pin = 0; pin < 16; ++pin)
    if (GPIO_Pin & (1u << pin)) r.write_pin(key(GPIOx, pin), PinState != GPIO_PIN_RESET);
}

void HAL_GPIO_TogglePin(GPIO_TypeDef* GPIOx, uint16_t GPIO_Pin) {
  FirmwareRuntime& r = call();
  if (!valid_port(GPIOx)) return;
  for (unsigned pin = 0; pin < 16; ++pin)
    if (GPIO_Pin & (1u << pin)) r.write_pin(key(GPIOx, pin), !r.pin_latch(key(GPIOx, pin)));
}

HAL_StatusTypeDef HAL_GPIO_LockPin(GPIO_TypeDef*, uint16_t) {
  call();
  return HAL_OK;
}

void HAL_GPIO_EXTI_IRQHandler(uint16_t GPIO_Pin) {
  rt();
  const std::uint32_t lines = g.pending & GPIO_Pin;
  for (unsigned line = 0; line < 16; ++line) {
    if (!(lines & (1u << line))) continue;
    g.pending &= ~(1u << line);
    const auto pin = static_cast<uint16_t>(1u << line);
    HAL_GPIO_EXTI_Callback(pin);
    if (g.rose[line])
      HAL_GPIO_EXTI_Rising_Callback(pin);
    else
      HAL_GPIO_EXTI_Falling_Callback(pin);
  }
}

__weak void HAL_GPIO_EXTI_Callback(uint16_t) {}
__weak void HAL_GPIO_EXTI_Rising_Callback(uint16_t) {}
__weak void HAL_GPIO_EXTI_Falling_Callback(uint16_t) {}

uint32_t l6470emu_exti_pending(uint32_t lines) { return g.pending & lines; }
void l6470emu_exti_clear(uint32_t lines) { g.pending &= ~lines; }

__weak void EXTI0_IRQHandler(void) { handle_lines(0x0001); }
__weak void EXTI1_IRQHandler(void) { handle_lines(0x0002); }
__weak void EXTI2_IRQHandler(void) { handle_lines(0x0004); }
__weak void EXTI3_IRQHandler(void) { handle_lines(0x0008); }
__weak void EXTI4_IRQHandler(void) { handle_lines(0x0010); }
__weak void EXTI9_5_IRQHandler(void) { handle_lines(0x03E0); }
__weak void EXTI15_10_IRQHandler(void) { handle_lines(0xFC00); }
__weak void EXTI0_1_IRQHandler(void) { handle_lines(0x0003); }
__weak void EXTI2_3_IRQHandler(void) { handle_lines(0x000C); }
__weak void EXTI4_15_IRQHandler(void) { handle_lines(0xFFF0); }

// ---------------------------------------------------------------- NVIC

void HAL_NVIC_SetPriorityGrouping(uint32_t) { call(); }
void HAL_NVIC_SetPriority(IRQn_Type, uint32_t, uint32_t) { call(); }

void HAL_NVIC_EnableIRQ(IRQn_Type IRQn) {
  FirmwareRuntime& r = call();
  if (l6470emu_tim_nvic(IRQn, true)) return r.spend(0);  // a timer's vector (hal_tim.cpp)
  const int v = vector_of_irqn(IRQn);
  if (v < 0) return;
  g.enabled[static_cast<std::size_t>(v)] = true;
  r.set_irq_enabled(g.irq[static_cast<std::size_t>(v)], true);
  if (g.pending & lines_of_vector(v)) r.pend_irq(g.irq[static_cast<std::size_t>(v)]);  // a line already pending
  r.spend(0);
}

void HAL_NVIC_DisableIRQ(IRQn_Type IRQn) {
  FirmwareRuntime& r = call();
  if (l6470emu_tim_nvic(IRQn, false)) return;
  const int v = vector_of_irqn(IRQn);
  if (v < 0) return;
  g.enabled[static_cast<std::size_t>(v)] = false;
  r.set_irq_enabled(g.irq[static_cast<std::size_t>(v)], false);
}

void HAL_NVIC_SetPendingIRQ(IRQn_Type IRQn) {
  FirmwareRuntime& r = call();
  if (const int v = vector_of_irqn(IRQn); v >= 0) r.pend_irq(g.irq[static_cast<std::size_t>(v)]);
}

void HAL_NVIC_ClearPendingIRQ(IRQn_Type IRQn) {
  FirmwareRuntime& r = call();
  if (const int v = vector_of_irqn(IRQn); v >= 0) r.clear_irq(g.irq[static_cast<std::size_t>(v)]);
}

uint32_t HAL_SYSTICK_Config(uint32_t) { return 0; }

// ---------------------------------------------------------------- RCC and PWR

HAL_StatusTypeDef HAL_RCC_OscConfig(RCC_OscInitTypeDef*) {
  call();
  return HAL_OK;
}
HAL_StatusTypeDef HAL_RCC_ClockConfig(RCC_ClkInitTypeDef*, uint32_t) {
  call();
  return HAL_OK;
}
HAL_StatusTypeDef HAL_RCCEx_PeriphCLKConfig(RCC_PeriphCLKInitTypeDef*) {
  call();
  return HAL_OK;
}
void HAL_RCC_MCOConfig(uint32_t, uint32_t, uint32_t) { call(); }
void HAL_RCC_EnableCSS(void) { call(); }
uint32_t HAL_RCC_GetSysClockFreq(void) { return SystemCoreClock; }
uint32_t HAL_RCC_GetHCLKFreq(void) { return SystemCoreClock; }
uint32_t HAL_RCC_GetPCLK1Freq(void) { return rt().timing().apb_clock_hz; }
uint32_t HAL_RCC_GetPCLK2Freq(void) { return rt().timing().apb_clock_hz; }
HAL_StatusTypeDef HAL_PWREx_EnableOverDrive(void) { return HAL_OK; }
HAL_StatusTypeDef HAL_PWREx_ControlVoltageScaling(uint32_t) { return HAL_OK; }
HAL_StatusTypeDef HAL_PWREx_ConfigSupply(uint32_t) { return HAL_OK; }
void HAL_PWR_EnableBkUpAccess(void) {}

// ---------------------------------------------------------------- SPI

__weak void HAL_SPI_MspInit(SPI_HandleTypeDef*) {}
__weak void HAL_SPI_MspDeInit(SPI_HandleTypeDef*) {}
__weak void HAL_SPI_TxCpltCallback(SPI_HandleTypeDef*) {}
__weak void HAL_SPI_RxCpltCallback(SPI_HandleTypeDef*) {}
__weak void HAL_SPI_TxRxCpltCallback(SPI_HandleTypeDef*) {}
__weak void HAL_SPI_ErrorCallback(SPI_HandleTypeDef*) {}

HAL_StatusTypeDef HAL_SPI_Init(SPI_HandleTypeDef* hspi) {
  FirmwareRuntime& r = call();
  if (!hspi || !hspi->Instance || hspi->Instance < l6470emu_spi_instances || hspi->Instance >= l6470emu_spi_instances + 6)
    return HAL_ERROR;
  if (hspi->State == HAL_SPI_STATE_RESET) {
    hspi->Lock = HAL_UNLOCKED;
    HAL_SPI_MspInit(hspi);
  }
  if (hspi->Init.Mode != SPI_MODE_MASTER) r.log("HAL_SPI_Init: only a master is modelled; the handle acts as one");
  if (hspi->Init.NSS == SPI_NSS_HARD_OUTPUT)
    r.log("HAL_SPI_Init: SPI_NSS_HARD_OUTPUT: a hardware chip select is not modelled; drive CS with HAL_GPIO_WritePin");
  if (hspi->Init.Direction != SPI_DIRECTION_2LINES)
    r.log("HAL_SPI_Init: only two-line full-duplex is modelled; the handle clocks both lines");
  hspi->ErrorCode = HAL_SPI_ERROR_NONE;
  hspi->State = HAL_SPI_STATE_READY;
  return HAL_OK;
}

HAL_StatusTypeDef HAL_SPI_DeInit(SPI_HandleTypeDef* hspi) {
  call();
  if (!hspi) return HAL_ERROR;
  HAL_SPI_MspDeInit(hspi);
  hspi->State = HAL_SPI_STATE_RESET;
  return HAL_OK;
}

HAL_StatusTypeDef HAL_SPI_Transmit(SPI_HandleTypeDef* hspi, const uint8_t* pData, uint16_t Size, uint32_t Timeout) {
  if (!pData) return HAL_ERROR;
  return spi_transfer(hspi, pData, nullptr, Size, Timeout, true);
}

HAL_StatusTypeDef HAL_SPI_Receive(SPI_HandleTypeDef* hspi, uint8_t* pData, uint16_t Size, uint32_t Timeout) {
  if (!pData) return HAL_ERROR;
  return spi_transfer(hspi, pData, pData, Size, Timeout, true);  // the buffer goes out on MOSI, as ST's does
}

HAL_StatusTypeDef HAL_SPI_TransmitReceive(SPI_HandleTypeDef* hspi, const uint8_t* pTxData, uint8_t* pRxData,
                                          uint16_t Size, uint32_t Timeout) {
  if (!pTxData || !pRxData) return HAL_ERROR;
  return spi_transfer(hspi, pTxData, pRxData, Size, Timeout, true);
}

HAL_StatusTypeDef HAL_SPI_Transmit_IT(SPI_HandleTypeDef* hspi, const uint8_t* pData, uint16_t Size) {
  const HAL_StatusTypeDef s = pData ? spi_transfer(hspi, pData, nullptr, Size, 0, false) : HAL_ERROR;
  if (s == HAL_OK) HAL_SPI_TxCpltCallback(hspi);
  return s;
}
HAL_StatusTypeDef HAL_SPI_Receive_IT(SPI_HandleTypeDef* hspi, uint8_t* pData, uint16_t Size) {
  const HAL_StatusTypeDef s = pData ? spi_transfer(hspi, pData, pData, Size, 0, false) : HAL_ERROR;
  if (s == HAL_OK) HAL_SPI_RxCpltCallback(hspi);
  return s;
}
HAL_StatusTypeDef HAL_SPI_TransmitReceive_IT(SPI_HandleTypeDef* hspi, const uint8_t* pTxData, uint8_t* pRxData,
                                             uint16_t Size) {
  const HAL_StatusTypeDef s = pTxData && pRxData ? spi_transfer(hspi, pTxData, pRxData, Size, 0, false) : HAL_ERROR;
  if (s == HAL_OK) HAL_SPI_TxRxCpltCallback(hspi);
  return s;
}
HAL_StatusTypeDef HAL_SPI_Transmit_DMA(SPI_HandleTypeDef* hspi, const uint8_t* pData, uint16_t Size) {
  return HAL_SPI_Transmit_IT(hspi, pData, Size);
}
HAL_StatusTypeDef HAL_SPI_Receive_DMA(SPI_HandleTypeDef* hspi, uint8_t* pData, uint16_t Size) {
  return HAL_SPI_Receive_IT(hspi, pData, Size);
}
HAL_StatusTypeDef HAL_SPI_TransmitReceive_DMA(SPI_HandleTypeDef* hspi, const uint8_t* pTxData, uint8_t* pRxData,
                                              uint16_t Size) {
  return HAL_SPI_TransmitReceive_IT(hspi, pTxData, pRxData, Size);
}

HAL_SPI_StateTypeDef HAL_SPI_GetState(SPI_HandleTypeDef* hspi) { return hspi ? hspi->State : HAL_SPI_STATE_RESET; }
uint32_t HAL_SPI_GetError(SPI_HandleTypeDef* hspi) { return hspi ? hspi->ErrorCode : 0; }

}  // extern "C"
