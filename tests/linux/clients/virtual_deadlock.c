/* Programs that wait for what can never come, and programs that only look as if they did, under
   time=virtual. Usage: virtual_deadlock MODE. Each deadlocked MODE blocks for ever on a real
   kernel (an idle chip's BUSY line never changes); the emulator must end it with its deadlock
   report and exit status. The others must end normally (exit 0): something outside the covered
   calls (a real timer, another process, a thread blocked in a pipe) can still wake them. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <linux/gpio.h>
#include <poll.h>
#include <pthread.h>
#include <semaphore.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/select.h>
#include <sys/syscall.h>
#include <sys/timerfd.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* The BUSY line of chip 0 (offset 0) with edge events, as libgpiod 2.x asks for it. */
static int busy_request(void) {
  int chip = open("/dev/gpiochip0", O_RDWR | O_CLOEXEC);
  if (chip < 0) {
    perror("open /dev/gpiochip0");
    exit(1);
  }
  struct gpio_v2_line_request req;
  memset(&req, 0, sizeof req);
  req.offsets[0] = 0;
  req.num_lines = 1;
  req.config.flags = GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_EDGE_RISING | GPIO_V2_LINE_FLAG_EDGE_FALLING;
  strcpy(req.consumer, "deadlock");
  if (ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &req) < 0) {
    perror("GPIO_V2_GET_LINE");
    exit(1);
  }
  return req.fd;
}

static int line_fd;

/* A real pause, not seen by the preload (so it does not move virtual time). */
static void real_sleep_ms(long ms) {
  struct timespec ts = {ms / 1000, (ms % 1000) * 1000000};
  syscall(SYS_nanosleep, &ts, NULL);
}

static void read_event(void) {
  struct gpio_v2_line_event ev;
  const ssize_t n = read(line_fd, &ev, sizeof ev);
  printf("read returned %zd (errno %d)\n", n, n < 0 ? errno : 0);
}

static void* reader(void* arg) {
  (void)arg;
  read_event();
  return NULL;
}

static pthread_mutex_t mutex = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t cond = PTHREAD_COND_INITIALIZER;

static void* cond_waiter(void* arg) {
  (void)arg;
  pthread_mutex_lock(&mutex);
  pthread_cond_wait(&cond, &mutex); /* nobody signals it */
  pthread_mutex_unlock(&mutex);
  return NULL;
}

static int pipe_fds[2];

static void* pipe_reader(void* arg) {
  (void)arg;
  char c = 0;
  /* Blocked outside the covered calls: counts as running, so no deadlock while it is here. */
  const ssize_t n = read(pipe_fds[0], &c, 1);
  printf("pipe reader got %zd byte '%c'\n", n, c);
  fflush(stdout);
  return NULL;
}

static void on_alarm(int sig) { (void)sig; }

int main(int argc, char** argv) {
  const char* mode = argc > 1 ? argv[1] : "read";
  setvbuf(stdout, NULL, _IOLBF, 0);
  line_fd = busy_request();
  printf("mode %s\n", mode);

  /* ---- deadlocks ---- */
  if (strcmp(mode, "read") == 0) {
    read_event();
  } else if (strcmp(mode, "poll") == 0) {
    struct pollfd p = {line_fd, POLLIN, 0};
    poll(&p, 1, -1);
  } else if (strcmp(mode, "ppoll") == 0) {
    struct pollfd p = {line_fd, POLLIN, 0};
    ppoll(&p, 1, NULL, NULL);
  } else if (strcmp(mode, "select") == 0) {
    fd_set r;
    FD_ZERO(&r);
    FD_SET(line_fd, &r);
    select(line_fd + 1, &r, NULL, NULL, NULL);
  } else if (strcmp(mode, "epoll") == 0) {
    int ep = epoll_create1(EPOLL_CLOEXEC);
    struct epoll_event ev = {EPOLLIN, {.fd = line_fd}};
    epoll_ctl(ep, EPOLL_CTL_ADD, line_fd, &ev);
    struct epoll_event out;
    epoll_wait(ep, &out, 1, -1);
  } else if (strcmp(mode, "threads") == 0) {
    pthread_t t;
    pthread_create(&t, NULL, reader, NULL);
    pthread_join(t, NULL);
  } else if (strcmp(mode, "cond") == 0) {
    pthread_t t;
    pthread_create(&t, NULL, cond_waiter, NULL);
    pthread_join(t, NULL);
  } else if (strcmp(mode, "sem") == 0) {
    sem_t s;
    sem_init(&s, 0, 0);
    sem_wait(&s);
  } else if (strcmp(mode, "sleep-forever") == 0) {
    struct timespec forever = {INT64_MAX, 999999999};
    nanosleep(&forever, NULL);
  } else if (strcmp(mode, "timerfd") == 0) {
    int tfd = timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC); /* never armed */
    uint64_t n;
    read(tfd, &n, sizeof n);
  } else if (strcmp(mode, "outside-thread") == 0) {
    /* A thread in a pipe read (not covered) holds off the verdict until a child writes to the
       pipe in real time; then only the main thread's poll of the idle line is left. */
    pipe(pipe_fds);
    pthread_t t;
    pthread_create(&t, NULL, pipe_reader, NULL);
    if (fork() == 0) {
      real_sleep_ms(300);
      write(pipe_fds[1], "x", 1);
      _exit(0);
    }
    struct pollfd p = {line_fd, POLLIN, 0};
    poll(&p, 1, -1);

  /* ---- not deadlocks ---- */
  } else if (strcmp(mode, "alarm") == 0) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_alarm;
    sigaction(SIGALRM, &sa, NULL);
    alarm(1); /* a real timer: its signal ends the read */
    read_event();
  } else if (strcmp(mode, "pipe") == 0) {
    /* A descriptor another process writes to (in real time) beside the idle line. */
    pipe(pipe_fds);
    if (fork() == 0) {
      real_sleep_ms(300);
      write(pipe_fds[1], "x", 1);
      _exit(0);
    }
    struct pollfd p[2] = {{line_fd, POLLIN, 0}, {pipe_fds[0], POLLIN, 0}};
    const int n = poll(p, 2, -1);
    printf("poll returned %d, pipe readable %d\n", n, (p[1].revents & POLLIN) != 0);
    wait(NULL);
  } else if (strcmp(mode, "shared-sem") == 0) {
    /* A process-shared semaphore: another process may post it (here, in real time). */
    sem_t* s = mmap(NULL, sizeof(sem_t), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    sem_init(s, 1, 0);
    if (fork() == 0) {
      real_sleep_ms(300);
      sem_post(s);
      _exit(0);
    }
    printf("sem_wait returned %d\n", sem_wait(s));
    wait(NULL);
  } else {
    fprintf(stderr, "unknown mode %s\n", mode);
    return 2;
  }
  printf("done\n");
  return 0;
}
