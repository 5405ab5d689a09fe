/* The edges of time under time=virtual, every covered entry point: timespecs the kernel refuses
   (EINVAL), timeouts it saturates at KTIME_MAX (they never end: a thread sleeping so is woken by
   another, and time does not jump), and select()'s microseconds that carry into seconds. Prints
   name=value lines; the clocks must never wrap or go back. Exits 1 on an unexpected result. */
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
#include <unistd.h>

static int64_t ns_of(clockid_t c) {
  struct timespec ts;
  clock_gettime(c, &ts);
  return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static int failures = 0;
static void check(int ok, const char* what) {
  if (!ok) {
    printf("unexpected: %s (errno %d)\n", what, errno);
    failures++;
  }
}

static const struct timespec kForever = {INT64_MAX, 999999999};

/* Prints "name=result/errno" of a call returning -1 and setting errno. */
#define REFUSED(name, call)                           \
  do {                                                \
    errno = 0;                                        \
    const int r_ = (call);                            \
    const int e_ = errno;                             \
    printf("%s=%d/%d\n", name, r_, e_);               \
  } while (0)

/* ---- waits that never end until another thread ends them ---- */

static void* sleep_forever(void* arg) {
  const int absolute = arg != NULL;
  int r = absolute ? clock_nanosleep(CLOCK_REALTIME, TIMER_ABSTIME, &kForever, NULL) : nanosleep(&kForever, NULL);
  printf("a sleep forever returned %d\n", r); /* never printed: the thread is cancelled */
  return NULL;
}

static void* select_forever(void* arg) {
  (void)arg;
  struct timeval tv = {INT64_MAX, 999999};
  select(0, NULL, NULL, NULL, &tv);
  return NULL;
}

static void* pselect_forever(void* arg) {
  (void)arg;
  pselect(0, NULL, NULL, NULL, &kForever, NULL);
  return NULL;
}

static void* ppoll_forever(void* arg) {
  (void)arg;
  ppoll(NULL, 0, &kForever, NULL);
  return NULL;
}

static void* epoll_forever(void* arg) {
  (void)arg;
  int ep = epoll_create1(EPOLL_CLOEXEC);
  struct epoll_event ev;
  epoll_pwait2(ep, &ev, 1, &kForever, NULL);
  return NULL;
}

static sem_t sem;
static pthread_mutex_t mutex = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t cond = PTHREAD_COND_INITIALIZER;
static int signalled = 0;
static int64_t woke_at[2];

static void* sem_forever(void* arg) {
  (void)arg;
  const int r = sem_timedwait(&sem, &kForever);
  woke_at[0] = ns_of(CLOCK_MONOTONIC);
  printf("sem_timedwait_forever=%d\n", r);
  return NULL;
}

static void* cond_forever(void* arg) {
  (void)arg;
  pthread_mutex_lock(&mutex);
  int r = 0;
  while (!signalled && r == 0) r = pthread_cond_timedwait(&cond, &mutex, &kForever);
  pthread_mutex_unlock(&mutex);
  woke_at[1] = ns_of(CLOCK_MONOTONIC);
  printf("cond_timedwait_forever=%d\n", r);
  return NULL;
}

static void* timerfd_forever(void* arg) {
  (void)arg;
  int t = timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC);
  struct itimerspec v = {{0, 0}, kForever};
  check(timerfd_settime(t, 0, &v, NULL) == 0, "timerfd_settime of KTIME_MAX");
  struct itimerspec left;
  timerfd_gettime(t, &left);
  printf("timerfd_forever_left_s_positive=%d\n", left.it_value.tv_sec > 1000000000);
  uint64_t n;
  read(t, &n, sizeof n);
  return NULL;
}

static void on_alarm(int sig) { (void)sig; }

int main(void) {
  setvbuf(stdout, NULL, _IOLBF, 0);
  const int64_t mono0 = ns_of(CLOCK_MONOTONIC), real0 = ns_of(CLOCK_REALTIME);

  /* ---- what the kernel refuses ---- */
  const struct timespec minus = {-1, 0}, bad_ns = {0, 1000000000}, neg_ns = {0, -1};
  printf("clock_nanosleep_abs_negative=%d\n", clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &minus, NULL));
  printf("clock_nanosleep_rel_negative=%d\n", clock_nanosleep(CLOCK_MONOTONIC, 0, &minus, NULL));
  printf("clock_nanosleep_abs_bad_ns=%d\n", clock_nanosleep(CLOCK_REALTIME, TIMER_ABSTIME, &bad_ns, NULL));
  REFUSED("nanosleep_negative", nanosleep(&minus, NULL));
  REFUSED("nanosleep_negative_ns", nanosleep(&neg_ns, NULL));
  struct timeval tv_neg = {0, -1};
  REFUSED("select_negative_usec", select(0, NULL, NULL, NULL, &tv_neg));
  REFUSED("pselect_bad_ns", pselect(0, NULL, NULL, NULL, &bad_ns, NULL));
  REFUSED("ppoll_negative", ppoll(NULL, 0, &minus, NULL));
  sem_init(&sem, 0, 0);
  REFUSED("sem_timedwait_bad_ns", sem_timedwait(&sem, &bad_ns));
  REFUSED("sem_timedwait_negative", sem_timedwait(&sem, &minus));
  int t = timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC);
  struct itimerspec bad = {{0, 0}, {-1, 0}};
  REFUSED("timerfd_settime_negative", timerfd_settime(t, 0, &bad, NULL));
  close(t);
  printf("after_refusals_ns=%lld\n", (long long)(ns_of(CLOCK_MONOTONIC) - mono0));

  /* ---- two sleeps of {INT64_MAX, 999999999}: each never ends, but for a real timer's signal;
     the clocks do not move (they used to jump 146 years, then wrap to 0) ---- */
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_alarm;
  sigaction(SIGALRM, &sa, NULL);
  for (int i = 0; i < 2; ++i) {
    const struct itimerval in_50ms = {{0, 0}, {0, 50000}};
    setitimer(ITIMER_REAL, &in_50ms, NULL);
    struct timespec rem = {0, 0};
    errno = 0;
    const int r = nanosleep(&kForever, &rem);
    const int e = errno;
    printf("nanosleep_forever_%d=%d/%d rem_beyond_2262=%d\n", i, r, e, rem.tv_sec > 9000000000LL);
  }
  printf("after_forever_sleeps_ns=%lld,%lld\n", (long long)(ns_of(CLOCK_MONOTONIC) - mono0),
         (long long)(ns_of(CLOCK_REALTIME) - real0));

  /* ---- select's microseconds carry into seconds: 2.5 s ---- */
  int64_t before = ns_of(CLOCK_MONOTONIC);
  struct timeval tv = {0, 2500000};
  const int sel = select(0, NULL, NULL, NULL, &tv);
  printf("select_2500000us=%d/%lld\n", sel, (long long)(ns_of(CLOCK_MONOTONIC) - before));

  /* ---- timeouts saturated at KTIME_MAX never end: another thread ends them ---- */
  pthread_t forever[8];
  pthread_create(&forever[0], NULL, sleep_forever, NULL);
  pthread_create(&forever[1], NULL, sleep_forever, (void*)1);
  pthread_create(&forever[2], NULL, select_forever, NULL);
  pthread_create(&forever[3], NULL, pselect_forever, NULL);
  pthread_create(&forever[4], NULL, ppoll_forever, NULL);
  pthread_create(&forever[5], NULL, epoll_forever, NULL);
  pthread_create(&forever[6], NULL, timerfd_forever, NULL);
  pthread_t sem_thread, cond_thread;
  pthread_create(&sem_thread, NULL, sem_forever, NULL);
  pthread_create(&cond_thread, NULL, cond_forever, NULL);
  before = ns_of(CLOCK_MONOTONIC);
  sleep(1); /* time goes to here, not to any of theirs */
  const int64_t slept = ns_of(CLOCK_MONOTONIC) - before;
  printf("slept_beside_forever=%lld\n", (long long)slept);
  sem_post(&sem);
  pthread_mutex_lock(&mutex);
  signalled = 1;
  pthread_cond_signal(&cond);
  pthread_mutex_unlock(&mutex);
  pthread_join(sem_thread, NULL);
  pthread_join(cond_thread, NULL);
  printf("woken_at_ns=%lld,%lld\n", (long long)(woke_at[0] - before), (long long)(woke_at[1] - before));
  for (int i = 0; i < 7; ++i) {
    pthread_cancel(forever[i]);
    pthread_join(forever[i], NULL);
  }

  /* ---- the clocks: exactly the finite sleeps, never wrapped ---- */
  const int64_t mono = ns_of(CLOCK_MONOTONIC) - mono0, real = ns_of(CLOCK_REALTIME) - real0;
  printf("monotonic_elapsed=%lld\n", (long long)mono);
  printf("realtime_elapsed=%lld\n", (long long)real);
  printf("failures=%d\n", failures);
  return failures ? 1 : 0;
}
