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
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/uio.h>
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
  /* Waits on a pipe a child holds: another process may write it, so no deadlock while it is here. */
  const ssize_t n = read(pipe_fds[0], &c, 1);
  printf("pipe reader got %zd byte '%c'\n", n, c);
  fflush(stdout);
  return NULL;
}

static void on_alarm(int sig) { (void)sig; }

/* Virtual time since the program's start, ms. */
static long start_ms = -1;
static long now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  const long ms = ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
  if (start_ms < 0) start_ms = ms;
  return ms - start_ms;
}

/* Sleeps 100 ms of virtual time, then writes one byte to the pipe. */
static void* late_writer(void* arg) {
  (void)arg;
  usleep(100000);
  write(pipe_fds[1], "y", 1);
  return NULL;
}

static pthread_mutex_t mutex_a = PTHREAD_MUTEX_INITIALIZER, mutex_b = PTHREAD_MUTEX_INITIALIZER;
static sem_t a_taken, b_taken;

/* Takes A, waits until the other thread has B, then wants B. */
static void* abba_first(void* arg) {
  (void)arg;
  pthread_mutex_lock(&mutex_a);
  sem_post(&a_taken);
  sem_wait(&b_taken);
  pthread_mutex_lock(&mutex_b);
  return NULL;
}

/* Takes B, waits until the other thread has A, then wants A. */
static void* abba_second(void* arg) {
  (void)arg;
  pthread_mutex_lock(&mutex_b);
  sem_post(&b_taken);
  sem_wait(&a_taken);
  pthread_mutex_lock(&mutex_a);
  return NULL;
}

/* Holds A across 100 ms of virtual sleep. */
static void* sleeping_holder(void* arg) {
  (void)arg;
  pthread_mutex_lock(&mutex_a);
  sem_post(&a_taken);
  usleep(100000);
  pthread_mutex_unlock(&mutex_a);
  return NULL;
}

/* Holds A while it computes (no covered call: it counts as running). */
static volatile unsigned long sink;
static void* computing_holder(void* arg) {
  (void)arg;
  pthread_mutex_lock(&mutex_a);
  sem_post(&a_taken);
  for (unsigned long i = 0; i < 200000000ul; ++i) sink += i;
  pthread_mutex_unlock(&mutex_a);
  return NULL;
}

static int socket_fds[2];

/* Sleeps 100 ms of virtual time, then sends one byte on the socket pair. */
static void* late_sender(void* arg) {
  (void)arg;
  usleep(100000);
  send(socket_fds[1], "s", 1, 0);
  return NULL;
}

static void recv_own_socket(void) {
  char c = 0;
  const ssize_t n = recv(socket_fds[0], &c, 1, 0);
  printf("recv returned %zd (errno %d) at %ld ms\n", n, n < 0 ? errno : 0, now_ms());
}

static void read_own_pipe(void) {
  char c = 0;
  const ssize_t n = read(pipe_fds[0], &c, 1);
  printf("read returned %zd (errno %d)\n", n, n < 0 ? errno : 0);
}

int main(int argc, char** argv) {
  const char* mode = argc > 1 ? argv[1] : "read";
  setvbuf(stdout, NULL, _IOLBF, 0);
  now_ms();
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
  } else if (strcmp(mode, "pipe-read") == 0) {
    pipe(pipe_fds); /* nobody else holds it, and nobody writes it */
    read_own_pipe();
  } else if (strcmp(mode, "pipe-readv") == 0) {
    pipe(pipe_fds);
    char c;
    struct iovec v = {&c, 1};
    readv(pipe_fds[0], &v, 1);
  } else if (strcmp(mode, "socketpair-recv") == 0) {
    socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, socket_fds); /* nobody else holds it */
    recv_own_socket();
  } else if (strcmp(mode, "pipe-read-threads") == 0) {
    /* Two threads read the same pipe; the main thread joins the first. */
    pipe(pipe_fds);
    pthread_t t1, t2;
    pthread_create(&t1, NULL, pipe_reader, NULL);
    pthread_create(&t2, NULL, pipe_reader, NULL);
    pthread_join(t1, NULL);
  } else if (strcmp(mode, "mutex-abba") == 0) {
    sem_init(&a_taken, 0, 0);
    sem_init(&b_taken, 0, 0);
    pthread_t t1, t2;
    pthread_create(&t1, NULL, abba_first, NULL);
    pthread_create(&t2, NULL, abba_second, NULL);
    pthread_join(t1, NULL);
  } else if (strcmp(mode, "mutex-self") == 0) {
    pthread_mutex_lock(&mutex_a);
    pthread_mutex_lock(&mutex_a); /* a plain mutex locked twice by its owner */
  } else if (strcmp(mode, "child-pause") == 0) {
    /* A child that waits for a signal nothing sends: it is deadlocked itself, and says so. */
    const pid_t child = fork();
    if (child == 0) {
      pause();
      _exit(0);
    }
    int status = 0;
    waitpid(child, &status, 0);
    printf("child exited %d\n", WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  } else if (strcmp(mode, "child-hung") == 0) {
    /* The child reads a pipe only the parent could write; the parent waits for the child. */
    pipe(pipe_fds);
    const pid_t child = fork();
    if (child == 0) {
      read_own_pipe();
      _exit(0);
    }
    waitpid(child, NULL, 0);
  } else if (strcmp(mode, "child-socketpair-hung") == 0) {
    /* The child waits on a socket pair only the parent could send on; the parent waits for it. */
    socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, socket_fds);
    const pid_t child = fork();
    if (child == 0) {
      recv_own_socket();
      _exit(0);
    }
    waitpid(child, NULL, 0);
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
  } else if (strcmp(mode, "pipe-read-thread") == 0) {
    /* Its own pipe, written by another thread after a virtual sleep: the read waits for it. */
    pipe(pipe_fds);
    pthread_t t;
    pthread_create(&t, NULL, late_writer, NULL);
    read_own_pipe();
    printf("at %ld ms\n", now_ms());
    pthread_join(t, NULL);
  } else if (strcmp(mode, "socketpair-recv-thread") == 0) {
    /* Its own socket pair, sent on by another thread after a virtual sleep. */
    socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, socket_fds);
    pthread_t t;
    pthread_create(&t, NULL, late_sender, NULL);
    recv_own_socket();
    pthread_join(t, NULL);
  } else if (strcmp(mode, "socketpair-recv-child") == 0) {
    /* Its own socket pair, sent on by a child in real time. */
    socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, socket_fds);
    if (fork() == 0) {
      real_sleep_ms(300);
      send(socket_fds[1], "c", 1, 0);
      _exit(0);
    }
    recv_own_socket();
    wait(NULL);
  } else if (strcmp(mode, "pipe-read-child") == 0) {
    /* Its own pipe, written by a child in real time. */
    pipe(pipe_fds);
    if (fork() == 0) {
      real_sleep_ms(300);
      write(pipe_fds[1], "x", 1);
      _exit(0);
    }
    read_own_pipe();
    wait(NULL);
  } else if (strcmp(mode, "pipe-read-alarm") == 0) {
    /* A read of its own pipe that a real timer's signal ends (a handler without SA_RESTART). */
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_alarm;
    sigaction(SIGALRM, &sa, NULL);
    pipe(pipe_fds);
    alarm(1);
    read_own_pipe();
  } else if (strcmp(mode, "mutex-sleeper") == 0 || strcmp(mode, "mutex-worker") == 0) {
    /* A mutex held by a thread that will release it: after its sleep, or after its work. */
    sem_init(&a_taken, 0, 0);
    pthread_t t;
    pthread_create(&t, NULL, strcmp(mode, "mutex-sleeper") == 0 ? sleeping_holder : computing_holder, NULL);
    sem_wait(&a_taken);
    pthread_mutex_lock(&mutex_a);
    printf("locked at %ld ms\n", now_ms());
    pthread_mutex_unlock(&mutex_a);
    pthread_join(t, NULL);
  } else if (strcmp(mode, "mutex-errorcheck") == 0) {
    /* An error-checking mutex its owner locks again: EDEADLK, as the C library says. */
    pthread_mutexattr_t attr;
    pthread_mutexattr_init(&attr);
    pthread_mutexattr_settype(&attr, PTHREAD_MUTEX_ERRORCHECK);
    pthread_mutex_t m;
    pthread_mutex_init(&m, &attr);
    pthread_mutex_lock(&m);
    printf("second lock %s\n", pthread_mutex_lock(&m) == EDEADLK ? "EDEADLK" : "other");
  } else if (strcmp(mode, "child-slow") == 0) {
    /* A child that takes 300 ms of real time, then exits 3: the parent waits for it. */
    const pid_t child = fork();
    if (child == 0) {
      real_sleep_ms(300);
      _exit(3);
    }
    int status = 0;
    waitpid(child, &status, 0);
    printf("child exited %d at %ld ms\n", WIFEXITED(status) ? WEXITSTATUS(status) : -1, now_ms());
  } else if (strcmp(mode, "child-fed") == 0) {
    /* The child reads a pipe the parent writes after 100 ms of its virtual time, then waits for it. */
    pipe(pipe_fds);
    const pid_t child = fork();
    if (child == 0) {
      read_own_pipe();
      _exit(0);
    }
    usleep(100000);
    write(pipe_fds[1], "z", 1);
    int status = 0;
    waitpid(child, &status, 0);
    printf("child exited %d\n", WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  } else if (strcmp(mode, "child-socketpair-fed") == 0) {
    /* The same, the parent sending after 100 ms of its virtual time. */
    socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, socket_fds);
    const pid_t child = fork();
    if (child == 0) {
      recv_own_socket();
      _exit(0);
    }
    usleep(100000);
    send(socket_fds[1], "p", 1, 0);
    int status = 0;
    waitpid(child, &status, 0);
    printf("child exited %d\n", WIFEXITED(status) ? WEXITSTATUS(status) : -1);
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
