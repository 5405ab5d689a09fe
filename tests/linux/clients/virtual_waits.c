/* Every kind of timed wait a C program makes, measured on its own CLOCK_MONOTONIC: under
   time=virtual each observed duration must be exactly the requested one. Prints name=ns lines
   (and a few results) for the test; exits 1 on an unexpected return value. */
#define _GNU_SOURCE
#include <errno.h>
#include <poll.h>
#include <pthread.h>
#include <semaphore.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/select.h>
#include <sys/time.h>
#include <sys/timerfd.h>
#include <time.h>
#include <sys/syscall.h>
#include <unistd.h>

static int64_t ns_of(clockid_t c) {
  struct timespec ts;
  clock_gettime(c, &ts);
  return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}
static int64_t now(void) { return ns_of(CLOCK_MONOTONIC); }

static struct timespec ts_of(int64_t ns) {
  struct timespec ts = {(time_t)(ns / 1000000000), (long)(ns % 1000000000)};
  return ts;
}

static int failures = 0;
static void check(int ok, const char* what) {
  if (!ok) {
    printf("unexpected: %s (errno %d)\n", what, errno);
    failures++;
  }
}

static int pipe_fds[2];
static sem_t sem;
static pthread_mutex_t mutex = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t cond = PTHREAD_COND_INITIALIZER;
static int flag = 0;

static void* post_after_13ms(void* arg) {
  (void)arg;
  usleep(13000);
  sem_post(&sem);
  return NULL;
}

static void* signal_after_14ms(void* arg) {
  (void)arg;
  usleep(14000);
  pthread_mutex_lock(&mutex);
  flag = 1;
  pthread_cond_signal(&cond);
  pthread_mutex_unlock(&mutex);
  return NULL;
}

static void* sleep_15ms(void* arg) {
  (void)arg;
  struct timespec d = ts_of(15000000);
  nanosleep(&d, NULL);
  return NULL;
}

static void* block_in_read(void* arg) {
  (void)arg;
  char c;
  /* A raw read system call: not a covered wait (read() of a pipe is one). */
  return (void*)(intptr_t)syscall(SYS_read, pipe_fds[0], &c, 1);
}

static void on_alarm(int sig) { (void)sig; }

static void unlock_mutex(void* m) { pthread_mutex_unlock((pthread_mutex_t*)m); }

static void* sleep_long(void* arg) {
  (void)arg;
  struct timespec d = ts_of(1000000000000LL);
  nanosleep(&d, NULL);
  return NULL;
}

static void* wait_forever(void* arg) {
  (void)arg;
  pthread_mutex_lock(&mutex);
  pthread_cleanup_push(unlock_mutex, &mutex);
  for (;;) pthread_cond_wait(&cond, &mutex);
  pthread_cleanup_pop(1);
  return NULL;
}

int main(void) {
  int64_t t0;
  check(pipe(pipe_fds) == 0, "pipe");

  t0 = now();
  struct timespec until = ts_of(t0 + 1250000);
  check(clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, NULL) == 0, "clock_nanosleep abs");
  printf("clock_nanosleep_abstime=%lld\n", (long long)(now() - t0));

  t0 = now();
  struct timespec d = ts_of(2000000);
  check(clock_nanosleep(CLOCK_REALTIME, 0, &d, NULL) == 0, "clock_nanosleep rel");
  printf("clock_nanosleep_realtime_relative=%lld\n", (long long)(now() - t0));

  t0 = now();
  d = ts_of(3000000);
  check(nanosleep(&d, NULL) == 0, "nanosleep");
  printf("nanosleep=%lld\n", (long long)(now() - t0));

  t0 = now();
  check(usleep(4000) == 0, "usleep");
  printf("usleep=%lld\n", (long long)(now() - t0));

  t0 = now();
  int64_t r0 = ns_of(CLOCK_REALTIME);
  struct timeval tv0;
  gettimeofday(&tv0, NULL);
  time_t s0 = time(NULL);
  check(sleep(2) == 0, "sleep");
  printf("sleep=%lld\n", (long long)(now() - t0));
  printf("realtime_during_sleep=%lld\n", (long long)(ns_of(CLOCK_REALTIME) - r0));
  struct timeval tv1;
  gettimeofday(&tv1, NULL);
  printf("gettimeofday_during_sleep_us=%lld\n",
         (long long)((tv1.tv_sec - tv0.tv_sec) * 1000000LL + (tv1.tv_usec - tv0.tv_usec)));
  printf("time_during_sleep_s=%lld\n", (long long)(time(NULL) - s0));

  fd_set rs;
  FD_ZERO(&rs);
  FD_SET(pipe_fds[0], &rs);
  struct timeval tv = {0, 5000};
  t0 = now();
  check(select(pipe_fds[0] + 1, &rs, NULL, NULL, &tv) == 0, "select");
  printf("select=%lld left=%ld\n", (long long)(now() - t0), (long)(tv.tv_sec * 1000000 + tv.tv_usec));

  FD_ZERO(&rs);
  FD_SET(pipe_fds[0], &rs);
  d = ts_of(5500000);
  t0 = now();
  check(pselect(pipe_fds[0] + 1, &rs, NULL, NULL, &d, NULL) == 0, "pselect");
  printf("pselect=%lld\n", (long long)(now() - t0));

  struct pollfd p = {pipe_fds[0], POLLIN, 0};
  t0 = now();
  check(poll(&p, 1, 6) == 0, "poll");
  printf("poll=%lld\n", (long long)(now() - t0));

  d = ts_of(6500000);
  t0 = now();
  check(ppoll(&p, 1, &d, NULL) == 0, "ppoll");
  printf("ppoll=%lld\n", (long long)(now() - t0));

  int ep = epoll_create1(EPOLL_CLOEXEC);
  struct epoll_event ev = {.events = EPOLLIN, .data.fd = pipe_fds[0]};
  epoll_ctl(ep, EPOLL_CTL_ADD, pipe_fds[0], &ev);
  t0 = now();
  check(epoll_wait(ep, &ev, 1, 7) == 0, "epoll_wait");
  printf("epoll_wait=%lld\n", (long long)(now() - t0));

  pthread_mutex_lock(&mutex);
  struct timespec abs_rt = ts_of(ns_of(CLOCK_REALTIME) + 8000000);
  t0 = now();
  check(pthread_cond_timedwait(&cond, &mutex, &abs_rt) == ETIMEDOUT, "pthread_cond_timedwait");
  printf("pthread_cond_timedwait_realtime=%lld\n", (long long)(now() - t0));
  pthread_mutex_unlock(&mutex);

  pthread_condattr_t ca;
  pthread_condattr_init(&ca);
  pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
  pthread_cond_t mono_cond;
  pthread_cond_init(&mono_cond, &ca);
  pthread_mutex_lock(&mutex);
  struct timespec abs_mono = ts_of(now() + 8500000);
  t0 = now();
  check(pthread_cond_timedwait(&mono_cond, &mutex, &abs_mono) == ETIMEDOUT, "pthread_cond_timedwait mono");
  printf("pthread_cond_timedwait_monotonic=%lld\n", (long long)(now() - t0));
  abs_mono = ts_of(now() + 9000000);
  t0 = now();
  check(pthread_cond_clockwait(&cond, &mutex, CLOCK_MONOTONIC, &abs_mono) == ETIMEDOUT, "pthread_cond_clockwait");
  printf("pthread_cond_clockwait=%lld\n", (long long)(now() - t0));
  pthread_mutex_unlock(&mutex);

  sem_init(&sem, 0, 0);
  abs_rt = ts_of(ns_of(CLOCK_REALTIME) + 10000000);
  t0 = now();
  check(sem_timedwait(&sem, &abs_rt) == -1 && errno == ETIMEDOUT, "sem_timedwait");
  printf("sem_timedwait=%lld\n", (long long)(now() - t0));
  abs_mono = ts_of(now() + 11000000);
  t0 = now();
  check(sem_clockwait(&sem, CLOCK_MONOTONIC, &abs_mono) == -1 && errno == ETIMEDOUT, "sem_clockwait");
  printf("sem_clockwait=%lld\n", (long long)(now() - t0));

  /* timerfd: a one-shot read blocking until it expires, then a periodic timer. */
  int tfd = timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC);
  struct itimerspec its = {{0, 0}, ts_of(12000000)};
  uint64_t count = 0;
  t0 = now();
  check(timerfd_settime(tfd, 0, &its, NULL) == 0, "timerfd_settime");
  check(read(tfd, &count, sizeof count) == sizeof count, "timerfd read");
  printf("timerfd_oneshot=%lld count=%llu\n", (long long)(now() - t0), (unsigned long long)count);
  its.it_interval = ts_of(1000000);
  its.it_value = ts_of(1000000);
  t0 = now();
  timerfd_settime(tfd, 0, &its, NULL);
  d = ts_of(5500000);
  nanosleep(&d, NULL);
  check(read(tfd, &count, sizeof count) == sizeof count, "timerfd read periodic");
  printf("timerfd_periodic_after_5.5ms count=%llu\n", (unsigned long long)count);
  struct pollfd tp = {tfd, POLLIN, 0};
  check(poll(&tp, 1, -1) == 1, "poll timerfd");
  printf("timerfd_poll=%lld\n", (long long)(now() - t0));
  struct itimerspec cur;
  timerfd_gettime(tfd, &cur);
  printf("timerfd_gettime_left=%lld\n", (long long)(cur.it_value.tv_sec * 1000000000LL + cur.it_value.tv_nsec));
  read(tfd, &count, sizeof count);
  epoll_ctl(ep, EPOLL_CTL_ADD, tfd, &(struct epoll_event){.events = EPOLLIN, .data.fd = tfd});
  t0 = now();
  check(epoll_wait(ep, &ev, 1, -1) == 1 && ev.data.fd == tfd, "epoll on timerfd");
  printf("timerfd_epoll=%lld\n", (long long)(now() - t0));
  close(tfd);

  /* Hand-offs between threads: a post, a signalled condition, a join. */
  pthread_t th;
  pthread_create(&th, NULL, post_after_13ms, NULL);
  t0 = now();
  check(sem_wait(&sem) == 0, "sem_wait");
  printf("sem_wait_for_a_post=%lld\n", (long long)(now() - t0));
  pthread_join(th, NULL);

  pthread_create(&th, NULL, signal_after_14ms, NULL);
  t0 = now();
  pthread_mutex_lock(&mutex);
  while (!flag) pthread_cond_wait(&cond, &mutex);
  pthread_mutex_unlock(&mutex);
  printf("cond_wait_for_a_signal=%lld\n", (long long)(now() - t0));
  pthread_join(th, NULL);

  pthread_create(&th, NULL, sleep_15ms, NULL);
  t0 = now();
  pthread_join(th, NULL);
  printf("join_of_a_sleeper=%lld\n", (long long)(now() - t0));

  /* pthread_cancel ends covered waits (a sleep, a condition wait that re-takes its mutex for the
     cleanup handler) without moving time. */
  pthread_t victims[2];
  pthread_create(&victims[0], NULL, sleep_long, NULL);
  pthread_create(&victims[1], NULL, wait_forever, NULL);
  d = ts_of(1000);
  nanosleep(&d, NULL); /* both are waiting by now: this sleep alone ended */
  t0 = now();
  int cancelled = 0;
  for (int i = 0; i < 2; i++) pthread_cancel(victims[i]);
  for (int i = 0; i < 2; i++) {
    void* res = NULL;
    pthread_join(victims[i], &res);
    cancelled += res == PTHREAD_CANCELED;
  }
  check(pthread_mutex_trylock(&mutex) == 0, "mutex released by the cleanup handler");
  pthread_mutex_unlock(&mutex);
  printf("cancelled=%d after=%lld\n", cancelled, (long long)(now() - t0));

  /* A real SIGALRM (timers stay real) interrupts a virtual sleep that cannot end: another thread
     is blocked in a call the library does not cover, and the config turns the idle grace off. */
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_alarm;
  sigaction(SIGALRM, &sa, NULL);
  pthread_create(&th, NULL, block_in_read, NULL);
  struct itimerval it = {{0, 0}, {0, 50000}};
  setitimer(ITIMER_REAL, &it, NULL);
  d = ts_of(100000000000LL);
  struct timespec rem = {0, 0};
  t0 = now();
  const int r = nanosleep(&d, &rem);
  printf("nanosleep_with_sigalrm=%d errno=%s elapsed=%lld rem=%lld\n", r, r == 0 ? "0" : strerror(errno),
         (long long)(now() - t0), (long long)(rem.tv_sec * 1000000000LL + rem.tv_nsec));
  check(write(pipe_fds[1], "x", 1) == 1, "write");
  pthread_join(th, NULL);

  printf("failures=%d\n", failures);
  return failures ? 1 : 0;
}
