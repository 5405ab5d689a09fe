// The emulated board's device nodes, as a transport serves them: a spidev node per chain and a
// gpiochip per chain carrying its chips' pins (and, on a chain with sck_pin=, the CS, SCK, MOSI
// and MISO lines a bit-banging host drives: device_board_spi_pins.cpp), in front of the OS-free Board (board/board.hpp),
// and the open files / line requests of the host programs, with the kernel's semantics
// (drivers/spi/spidev.c, drivers/gpio/gpiolib-cdev.c).
// Every open file or line request is a handle backed by a SOCK_SEQPACKET socketpair: the
// host program gets one end as its file descriptor (poll/read see edge events natively),
// the board keeps the other, and a handle lives until every copy of the host's end is closed.
// Used in process by the preload library and, behind a Unix socket, by `l6470emu serve`.
#pragma once

#include <linux/spi/spidev.h>

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "board/board.hpp"
#include "board/board_config.hpp"
#include "board/scenario.hpp"
#include "daisychain/chain.hpp"
#include "linux/clock.hpp"
#include "linux/gpio_lines.hpp"
#include "linux/log.hpp"
#include "linux/pwm_state.hpp"
#include "linux/spidev_rules.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

class ScenarioRunner;

/// What kind of open file a handle is.
enum class HandleKind : std::uint8_t {
  spidev = 1,           ///< an open /dev/spidevB.C
  gpiochip = 2,         ///< an open /dev/gpiochipN
  line_handle_v1 = 3,   ///< GPIO_GET_LINEHANDLE_IOCTL result
  line_event_v1 = 4,    ///< GPIO_GET_LINEEVENT_IOCTL result (reads struct gpioevent_data)
  line_request_v2 = 5,  ///< GPIO_V2_GET_LINE_IOCTL result (reads struct gpio_v2_line_event)
};

/// A device node the board provides.
struct DeviceNode {
  enum class Type : std::uint8_t { spidev, gpiochip } type;
  std::string path;      ///< "/dev/spidev0.0", "/dev/gpiochip0"
  std::string name;      ///< "spidev0.0", "gpiochip0" (sysfs name)
  unsigned major = 0;
  unsigned minor = 0;
  std::uint32_t bufsiz = 0;  ///< spidev: the bufsiz module parameter (EMSGSIZE limit)
};

/// A file the board created for a host program: result < 0 is -errno.
struct NewFile {
  long result = 0;
  std::uint64_t handle = 0;
  int fd = -1;  ///< the host's end; the caller owns it
  HandleKind kind = HandleKind::spidev;
};

/// What spi_message, spi_read and spi_write return when the message broke a rule of the chip
/// under check=error (board/sanitizer.hpp): the caller ends its host program's run with the
/// report (the preload: exit status kSanitizerExitStatus). Not an errno value.
inline constexpr long kCheckFailed = -0x5A17;

/// Called after every SPI message with the chain index, the message and the bytes (for
/// observers of the traffic; native traces are recorded by start_recording instead).
using MessageObserver = std::function<void(std::size_t chain, std::span<const spi_ioc_transfer> xfers,
                                           std::span<const std::uint8_t> tx, std::span<const std::uint8_t> rx,
                                           Tick end_tick)>;

/// The emulated hardware (a Board) and the kernel-side state of its device nodes. Thread-safe:
/// one lock covers the board and the nodes.
class DeviceBoard {
 public:
  /// Builds the chains and gpiochips of `config`; diagnostics go to `log`. The board's time is
  /// read from `host` (the kernel's clocks unless a test injects its own).
  DeviceBoard(const BoardConfig& config, DiagnosticLog& log, HostClock& host = real_host_clock());
  ~DeviceBoard();
  DeviceBoard(const DeviceBoard&) = delete;
  DeviceBoard& operator=(const DeviceBoard&) = delete;

  /// The device nodes, in a fixed order (index = device index for open()).
  const std::vector<DeviceNode>& nodes() const { return nodes_; }

  // ---- the host programs' side: what the kernel would do ---------------------

  /// open() of node `device`; `cloexec` makes the host's end close-on-exec.
  NewFile open(std::size_t device, bool cloexec);
  /// A host program closed a descriptor of `handle`: if no copy of it is left anywhere,
  /// the handle is released now (spidev's last-close reset, gpio lines freed).
  void closed(std::uint64_t handle);
  /// ioctl other than SPI_IOC_MESSAGE on `handle`. `arg` holds the _IOC_SIZE(cmd) argument bytes
  /// (copied in for _IOC_WRITE, copied out for _IOC_READ by the caller). A line request fills
  /// `created` (and the fd field of the argument struct). Returns >= 0 or -errno. A set of line
  /// values that drives an SPI line returns kSpiLineSetTicks of board time later (a wait in
  /// virtual time, a spin on the wall clock), the board unlocked meanwhile.
  long ioctl(std::uint64_t handle, unsigned long cmd, std::span<std::uint8_t> arg, NewFile* created);
  /// SPI_IOC_MESSAGE(n): `tx` holds the tx data of the transfers with a tx_buf, concatenated;
  /// `rx` (spidev_rx_bytes long) receives the rx data. Returns the total length or -errno.
  /// Like a kernel transfer, the call takes the message's bus time: the message starts when
  /// the bus is free (now, or when the message before it on the same bus ends) and the call
  /// returns when the board's time reaches its end (a sleep in wall mode, a wait in virtual mode).
  ///
  /// Under check=error, a message that breaks a rule of the chip still runs as the chip would
  /// take it; then the call returns kCheckFailed with the sanitizer's report in `check_report`
  /// (without one, -EIO: the report is in the log).
  ///
  /// `caller_alive` (a daemon's client, which may die while its message is on the bus): on the
  /// wall clock, a message longer than kBusSliceTicks is clocked a slice at a time, the caller
  /// sleeping out each slice's bus time and `caller_alive` asked between slices. When it says no,
  /// nothing more is clocked, CS rises, and the bus is free for the others at once (-EPIPE): a
  /// live client never waits out a dead one's bus time. Others on the bus wait for the message
  /// as they wait for any (the bus is its until it ends).
  long spi_message(std::uint64_t handle, std::span<const spi_ioc_transfer> xfers, std::span<const std::uint8_t> tx,
                   std::span<std::uint8_t> rx, std::string* check_report = nullptr,
                   const std::function<bool()>& caller_alive = {});
  /// read()/write() on a spidev: one rx-only / tx-only transfer. Returns the count or -errno
  /// (kCheckFailed as spi_message).
  long spi_read(std::uint64_t handle, std::span<std::uint8_t> rx, std::string* check_report = nullptr,
                const std::function<bool()>& caller_alive = {});
  long spi_write(std::uint64_t handle, std::span<const std::uint8_t> tx, std::string* check_report = nullptr,
                 const std::function<bool()>& caller_alive = {});

  /// What a line-values set (GPIOHANDLE_SET_LINE_VALUES_IOCTL, GPIO_V2_LINE_SET_VALUES_IOCTL) that
  /// drives a CS, SCK or MOSI line costs in board time: the call returns 1 µs after the edges,
  /// about what the kernel's gpio character device takes on a Raspberry Pi, so that a bit-banged
  /// frame keeps t_setCS and t_disCS in virtual time too. Other gpio calls cost no board time.
  static constexpr Tick kSpiLineSetTicks = 1 * kTicksPerMicrosecond;

  /// Bus time of one slice of a long message whose caller may die (10 ms).
  static constexpr Tick kBusSliceTicks = 10 * 1000 * kTicksPerMicrosecond;

  // ---- the driver sanitizer -------------------------------------------------------

  /// Where the board's diagnostics go.
  DiagnosticLog& log() { return log_; }
  /// The board's check settings (check=, check.allow=).
  CheckConfig check_config();
  /// Changes them (L6470EMU_CHECK over the description's check=).
  void set_check_config(const CheckConfig& config);

  // ---- the physical world (ctl, tests) ----------------------------------------

  std::size_t chain_count() const { return board_.chain_count(); }
  /// Index in nodes() of chain `chain`'s spidev node.
  std::size_t spidev_node(std::size_t chain) const;
  /// Number of chips of chain `chain`.
  std::size_t chip_count(std::size_t chain) const;
  /// How diagnostics and `ctl` number the chips (the config's numbering=). Chip arguments of
  /// DeviceBoard's own functions are always chain indices (0 drives MISO).
  NumberFrom numbering() const { return board_.numbering(); }
  /// The numbering of chain `chain`: its chain indices as users see them.
  ChipNumbering chip_numbering(std::size_t chain) const { return board_.chip_numbering(chain); }
  /// "spidev0.0 (3 x L6470, gpiochip0)".
  std::string chain_summary(std::size_t chain) const;
  /// Index of the chain on node path or name ("spidev0.0", "/dev/spidev0.0", "0.0"), or -1.
  int find_chain(const std::string& name) const;
  /// Runs `f` on chain `chain` brought up to the clock, then reports the pin edges it caused.
  void with_chain(std::size_t chain, const std::function<void(Chain&)>& f);
  /// Drives an input pin of chip `chip` (SW, STCK, STBY_RST) as the physical world would.
  /// Returns false for an output pin or a bad index.
  bool drive_pin(std::size_t chain, std::size_t chip, Pin pin, bool level);
  /// Level of a pin of a chip (what a host reading the line would see before active-low).
  bool pin_level(std::size_t chain, std::size_t chip, Pin pin);
  /// Virtual time: moves every chain on by `ticks` (edges reported on the way; recorded as an
  /// `advance` event). Wall time: false.
  bool advance(Tick ticks);
  /// Virtual time: moves the board's time to `tick` if it is later and brings every chain
  /// there, delivering the BUSY/FLAG edges of watched lines at their own ticks. Wall time: false.
  bool advance_to(Tick tick);
  /// The earliest tick at which a watched BUSY/FLAG line will change by itself (kNever: none).
  /// A host thread waiting on line events wakes then.
  Tick next_edge_tick();
  /// Current tick of chain `chain`.
  Tick now(std::size_t chain);
  /// The board's time (the one owner of the clock: spidev, gpio events, ctl, traces).
  BoardTime& time() { return board_.time(); }
  const BoardTime& time() const { return board_.time(); }
  /// Attaches (or with an empty function detaches) the SPI message observer.
  void set_message_observer(MessageObserver observer);
  /// A backdoor event (fault on/off, thermal class, ADCIN code) on chip `chip` of chain `chain`,
  /// recorded when the chain is being recorded. Returns false for a bad index.
  bool inject_fault(std::size_t chain, std::size_t chip, TraceFault fault, std::uint8_t value);
  /// Changes the load on the axis of chip `chip` (`ctl axis load`), recorded when the chain is
  /// being recorded. False for a bad index or a chip without an axis.
  bool set_axis_load(std::size_t chain, std::size_t chip, const LoadSpec& load);

  // ---- PWM (device_board_pwm.cpp): the kernel's pwm sysfs class on the chips' STCK ----------

  /// PWM channels of chain `chain`'s pwmchip: one per chip, channel K driving chip K's STCK (chain
  /// index, 0 nearest MISO, as the gpiochip numbers the chips' lines). 0 for a bad chain.
  std::size_t pwm_channels(std::size_t chain) const;
  /// A write of `text` to `attr` of chain `chain`'s pwmchip, as drivers/pwm/sysfs.c takes it:
  /// export/unexport (`channel` ignored: the text names it) or a channel's period, duty_cycle,
  /// enable, polarity. Returns text.size() or the kernel's -errno: -ENODEV for a channel past
  /// npwm or an unexport of one not exported, -EBUSY for a second export, -EINVAL/-ERANGE for bad
  /// text or a state pwm_apply refuses (pwm_state.hpp), -ENOENT for a channel not exported.
  /// An enabled channel drives a pulse train on the chip's STCK (Board::drive_pulse_train) with
  /// a 1 GHz count clock: period and duty are exact in nanoseconds, each edge at the board tick
  /// (250 ns) at or before it, without drift. Enabling starts a period (the pin rises) now (on
  /// the wall clock a microsecond on: the board's time moves while the call runs); a
  /// change while enabled takes effect at the pin's next rising edge (the next period, as a
  /// kernel PWM's); disabling or unexporting drives STCK low now, the pulses that rose up to now
  /// (one rising now included) counted.
  long pwm_write(std::size_t chain, int channel, PwmAttr attr, std::string_view text);
  /// A read of `attr` (npwm, or a channel's file): 0 with the text in `out`, or -errno (-ENOENT:
  /// a channel not exported; -ENODEV: a bad chain or channel; -EACCES: export/unexport).
  long pwm_read(std::size_t chain, int channel, PwmAttr attr, std::string& out);
  /// Whether channel `channel` of chain `chain` is exported.
  bool pwm_exported(std::size_t chain, std::size_t channel);
  /// The rising edges channel `channel`'s trains have made on STCK so far (Board::pulse_train_rises of the train on now).
  std::uint64_t pwm_rises(std::size_t chain, std::size_t channel);
  /// How the board's trains reached the chips (Board::pulse_train_counts: bulk or edge by edge).
  Board::PulseTrainCounts pulse_train_counts();

  // ---- trace recording (the Board's, under the lock) ---------------------------------

  /// Starts recording chain `chain` into a native trace at `path` (truncated; a recording in
  /// progress on the chain is stopped first): the chain's board description, every CS frame,
  /// every input pin change (host gpio or ctl), every backdoor event, axis load change and
  /// `advance`, and the BUSY/FLAG changes at their ticks (Board::start_recording). A plain file
  /// is written through a shared mapping, a gzip file flushed by size and host time.
  /// Returns "" or one line saying why not.
  std::string start_recording(std::size_t chain, const std::string& path);
  /// Starts recording every chain: into `path` for one chain, else trace_path_for_chain files.
  std::string start_recording_all(const std::string& path);
  /// Stops recording chain `chain` (a frame still open, CS held low, is not written).
  /// Returns false when it was not recording; `summary` gets "N frames to PATH".
  bool stop_recording(std::size_t chain, std::string* summary = nullptr);
  /// Where chain `chain` is being recorded ("" = not recording).
  std::string recording_path(std::size_t chain);
  /// After fork() in the child: drops the parent's recordings without writing to them.
  void forget_recordings_after_fork();

  // ---- a scenario (`l6470emu run`) -----------------------------------------------------

  /// Binds `scenario` to the board (board/scenario_runner.hpp): from now on advance_to fires its
  /// steps at their ticks, SPI messages its command steps (wall time: its due steps first).
  /// Throws std::invalid_argument (one line naming the step) when it does not fit the board.
  void set_scenario(const Scenario& scenario);
  /// Adds steps at a time or at the end to the bound scenario (ScenarioRunner::add_steps: a
  /// campaign's rerun forked from a snapshot). Throws std::invalid_argument; false: no scenario.
  bool add_scenario_steps(const std::vector<ScenarioStep>& steps);
  /// The tick of the scenario's next timed step (kNever: none, or no scenario).
  Tick scenario_next_tick();
  /// Ends the scenario at the board's time now (its `end` expectations judged). False: none.
  bool finish_scenario(ScenarioOutcome& out);
  /// Starts collecting interface coverage on every chain (Board::enable_coverage).
  void enable_coverage();
  /// What the run has met so far (empty data when coverage is off); nullopt when `try_only` and
  /// another thread holds the board (a program exiting with a thread inside a transfer).
  std::optional<CoverageData> coverage(bool try_only = false);

  /// The driver sanitizer's first report for a caller that could not be ended (a kernel node's:
  /// its call failed with EIO and the report went to the log); nullopt while none. `run
  /// --nodes kernel` ends with it.
  std::optional<std::string> first_unended_check_failure();

  /// Open handles, by kind, as text (for `ctl dump`).
  std::string describe_handles();

  /// Starts the thread that delivers BUSY/FLAG edges on time in wall mode and notices host
  /// ends closed in other processes. Started on demand; the daemon starts it at once.
  void start_pump();
  /// Stops it (also done by the destructor).
  void stop_pump();
  /// After fork() in the child: the pump thread did not survive; forget it (restarted on demand).
  void forget_pump_after_fork();
  /// The lock of the whole board (for fork handlers).
  std::mutex& mutex() { return m_; }

 private:
  struct ChainDev;
  struct LineDev;
  struct GpioDev;
  struct Handle;

  Handle* find(std::uint64_t id, HandleKind kind);
  Handle* find_any(std::uint64_t id);
  NewFile make_handle(HandleKind kind, std::size_t dev, bool cloexec, std::unique_ptr<Handle>& out);
  void release(Handle& h);
  void release_if_closed(std::uint64_t id);

  // time and edges
  long run_spi_message(std::uint64_t handle, std::span<const spi_ioc_transfer> xfers, std::span<const std::uint8_t> tx,
                       std::span<std::uint8_t> rx, Tick& end, std::string* check_report,
                       const std::function<bool()>& caller_alive);
  /// A clocked message's end: the observer, then the sanitizer's verdict (kCheckFailed / -EIO
  /// under check=error) or `total`.
  long finish_spi_message(std::size_t chain, std::span<const spi_ioc_transfer> xfers, std::span<const std::uint8_t> tx,
                          std::span<std::uint8_t> rx, Tick end, long total, std::string* check_report);
  /// Waits (the lock held by `lock`) until no sliced message owns `bus`.
  void wait_for_bus(std::unique_lock<std::mutex>& lock, unsigned bus);
  void wait_for(Tick tick);
  void report_edge(const PinEdge& edge);
  void watch_line(GpioDev& g, unsigned offset, bool watched);
  bool physical_level(GpioDev& g, unsigned offset);
  void set_chip_input(GpioDev& g, unsigned offset, bool level);
  void send_line_event(Handle& h, unsigned index, bool rising, Tick tick);
  void notify_lineinfo(GpioDev& g, unsigned offset, std::uint32_t event_type);
  void wake_pump();
  void pump_loop();

  // gpio ioctls (device_board_gpio.cpp)
  long gpiochip_ioctl(Handle& h, unsigned long cmd, std::span<std::uint8_t> arg, NewFile* created);
  /// A line request's ioctl; `lasts_to`: the tick the call returns at (0: at once).
  long line_ioctl(Handle& h, unsigned long cmd, std::span<std::uint8_t> arg, Tick& lasts_to);
  /// ioctl() under the lock; `lasts_to` as line_ioctl's, waited for once the lock is released.
  long locked_ioctl(std::uint64_t handle, unsigned long cmd, std::span<std::uint8_t> arg, NewFile* created,
                    Tick& lasts_to);
  void fill_v2_info(GpioDev& g, unsigned offset, void* info);
  long request_lines(Handle& chip, HandleKind kind, const std::vector<unsigned>& offsets,
                     const std::vector<std::uint64_t>& flags, const std::vector<int>& values, const char* consumer,
                     std::uint32_t event_buffer_size, const std::vector<std::uint32_t>& debounce, NewFile* created);
  long reconfigure_lines(Handle& h, const std::vector<std::uint64_t>& flags, const std::vector<int>& values,
                         const std::vector<std::uint32_t>& debounce);
  bool logical_value(Handle& h, unsigned index);
  /// -EOPNOTSUPP (said in the log) when `flags` ask edge events of an SPI line, else 0.
  long refuse_spi_line_edges(GpioDev& g, const std::vector<unsigned>& offsets, const std::vector<std::uint64_t>& flags);
  /// A request's (or reconfiguration's) output values (`values`: -1 none, else 0/1 logical).
  void set_requested_values(GpioDev& g, const std::vector<unsigned>& offsets, const std::vector<int>& values);
  /// Sets the values of lines `indices` of request `h` (physical levels in `levels`, one per
  /// index), in offset order; returns the tick the call lasts to (0: it drove no SPI line).
  Tick apply_values(Handle& h, const std::vector<unsigned>& indices, const std::vector<bool>& levels);

  // PWM (device_board_pwm.cpp)
  struct PwmChannel {
    bool exported = false;
    PwmSettings settings;
    bool train_on = false;     ///< a pulse train drives STCK (else a steady level)
    PulseTrain train;          ///< the train last started
  };
  PwmChannel* pwm_channel(std::size_t chain, std::size_t chip);
  /// Makes the STCK of chip `chip` follow `next` (the channel's settings before in `ch`).
  void apply_pwm(std::size_t chain, std::size_t chip, PwmChannel& ch, const PwmSettings& next);
  /// Drives STCK of chip `chip` steadily to `level` now (through its gpio line when it has one).
  void set_stck_level(std::size_t chain, std::size_t chip, bool level);

  // SPI at the pins (device_board_spi_pins.cpp): the host drives CS, SCK, MOSI (or MISO,
  // which the chips ignore); `at_request`: set by a line request's default output value.
  void set_spi_line(GpioDev& g, SpiLine line, bool level, bool at_request);
  /// The level an SPI line reads (before active-low).
  bool spi_line_level(GpioDev& g, unsigned offset);

  DiagnosticLog& log_;
  Board board_;
  std::vector<DeviceNode> nodes_;
  std::vector<std::unique_ptr<ChainDev>> chains_;  // the spidev node of each chain of board_
  std::vector<std::unique_ptr<GpioDev>> gpios_;
  std::vector<int> node_target_;  // node index -> chain or gpio index
  std::unordered_map<std::uint64_t, std::unique_ptr<Handle>> handles_;
  std::mt19937_64 handle_ids_;  // seeded from getrandom(): handle ids are capabilities
  MessageObserver observer_;
  std::unique_ptr<ScenarioRunner> scenario_;
  std::optional<std::string> first_unended_check_failure_;
  std::vector<std::vector<PwmChannel>> pwm_;  // chain x chip, made on first use

  std::mutex m_;
  // Buses a sliced message owns until it ends (its caller sleeping between slices, the lock
  // released): other messages on them wait for bus_released_.
  std::unordered_map<unsigned, bool> bus_owned_;
  std::size_t sliced_in_flight_ = 0;
  std::condition_variable bus_released_;
  std::thread pump_;
  bool pump_running_ = false;
  bool pump_stop_ = false;
  int wake_fd_ = -1;
};

}  // namespace l6470emu
