/* raw_lcm_pingpong: the raw LCM baseline of the LCM latency benchmark. A plain C program over
 * liblcm and the C code `lcm-gen -c` generates from horus's own .lcm files (geometry.lcm,
 * vision.lcm, horus_bench.lcm); no horus code. It has the command line, channels and output of
 * horus-dds-pingpong run with HORUS_BACKEND=lcm, so the two are compared like for like:
 *
 *   raw-lcm-pingpong pong <unused_domain> <type> <seconds>
 *   raw-lcm-pingpong ping <unused_domain> <type> <round_trips> <warmup>
 *   raw-lcm-pingpong sink <unused_domain> <type> <seconds>      throughput: counts what arrives on
 *   raw-lcm-pingpong source <unused_domain> <type> <seconds>    bench.<type>.tput, sent back to back
 *     type: cmdvel | kilobyte | image   (image: 1920x1080 rgb8, 6,220,800 bytes of data)
 *
 * The LCM URL is $HORUS_LCM_URL, else liblcm's default ($LCM_DEFAULT_URL, else
 * udpm://239.255.76.67:7667?ttl=0). The domain argument is accepted and ignored (LCM has none).
 * Channels: bench.<type>.ping, bench.<type>.pong, bench.<type>.tput. The sequence number is
 * CmdVel.stamp_nanos, Kilobyte.seq or Image.timestamp_ns; -1 (UINT64_MAX as horus writes it) is
 * the stop marker.
 *
 * pong republishes every message of bench.<type>.ping on bench.<type>.pong. It prints "ready"
 * once subscribed and stops after <seconds>, when its stdin (a pipe) reaches EOF, or on the stop
 * marker. ping sends probes until the pong answers (30 s; LCM has no discovery), runs <warmup>
 * then <round_trips> round trips, sends the stop marker and prints
 *   RESULT impl=raw-lcm type=<type> n=<answered> p50_ns= p99_ns= p999_ns= mean_ns= [lost=<k>]
 * with the one-way latency (RTT/2), percentiles ranked as horus-dds-pingpong ranks them.
 * LCM is best effort: a round trip with no answer within 1 s (2 s for the image) counts as lost.
 *
 * sink prints "ready", counts the messages of bench.<type>.tput until the stop marker (or
 * <seconds>, or EOF on its stdin pipe), and prints
 *   RESULT impl=raw-lcm type=<type> mode=tput received=<n> seconds=<s> rate=<msgs/s> mbps=<MB/s> lost=<k>
 * timed from the first to the last counted message; MB are payload bytes (cmdvel 16, kilobyte
 * 1024, image 6,220,800 a message) as horus-dds-pingpong counts them; lost = highest sequence
 * number seen - messages counted (the source numbers from 1). source waits 200 ms (LCM has no
 * matching: start the sink first), publishes back to back for <seconds>, then the stop marker 5
 * times 30 ms apart (it opens no receive socket: it does not get its own messages back), and prints
 *   SENT impl=raw-lcm type=<type> sent=<n> seconds=<s> rate=<msgs/s> publish_errors=<k>
 *
 * Receiving is thread-free: poll() on lcm_get_fileno() (and stdin), then lcm_handle(), which
 * decodes and calls the typed handler in this thread. (horus instead handles in a background
 * thread and the user polls its ring: this is the fastest raw way.) BENCH_SPIN=1 polls with a
 * zero timeout and sched_yield() between empty polls, as horus-dds-pingpong's recv loop does.
 * Subscription queues are unlimited (set_queue_capacity 0). Exit: 0 ok, 1 nothing received,
 * 2 usage, 3 setup failure. */
#define _GNU_SOURCE
#include <errno.h>
#include <inttypes.h>
#include <poll.h>
#include <sched.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "horus_bench_Kilobyte.h"
#include "horus_msg_CmdVel.h"
#include "horus_msg_Image.h"
#include "horus_msg_ImageEncoding.h"

enum { kCmdVel, kKilobyte, kImage };
enum { kPing, kPong, kSink, kSource };
enum { kImageWidth = 1920, kImageHeight = 1080, kImageStep = kImageWidth * 3 };
#define kImageBytes ((int32_t)kImageStep * kImageHeight)
#define kStopSeq ((int64_t)-1) /* UINT64_MAX, the stop marker of horus-dds-pingpong */
#define kMatchDeadlineNs 30000000000ull
#define kProbeEveryNs 200000000ull
#define kIdlePollMs 100

static const char* kImpl = "raw-lcm";

static uint64_t now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static void sleep_ms(unsigned ms) {
  struct timespec ts = {(time_t)(ms / 1000u), (long)(ms % 1000u) * 1000000L};
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

static int usage(void) {
  fprintf(stderr,
          "usage: raw-lcm-pingpong pong <unused_domain> <type> <seconds>\n"
          "       raw-lcm-pingpong ping <unused_domain> <type> <round_trips> <warmup>\n"
          "       raw-lcm-pingpong sink <unused_domain> <type> <seconds>\n"
          "       raw-lcm-pingpong source <unused_domain> <type> <seconds>\n"
          "  type: cmdvel | kilobyte | image\n"
          "  HORUS_LCM_URL: the LCM URL (default: liblcm's); BENCH_SPIN=1: spin instead of blocking in poll()\n");
  return 2;
}

static int parse_u64(const char* s, uint64_t* out) {
  char* end = NULL;
  errno = 0;
  if (s == NULL || *s == '\0' || *s == '-') return 0;
  unsigned long long v = strtoull(s, &end, 10);
  if (errno != 0 || *end != '\0') return 0;
  *out = (uint64_t)v;
  return 1;
}

static int parse_seconds(const char* s, double* out) {
  char* end = NULL;
  errno = 0;
  if (s == NULL || *s == '\0') return 0;
  double v = strtod(s, &end);
  if (errno != 0 || *end != '\0' || !(v >= 0) || v > 1e6) return 0;
  *out = v;
  return 1;
}

/* ---- the state the typed handlers share ------------------------------------------------------ */

struct bench {
  lcm_t* lcm;
  int fd;          /* lcm_get_fileno */
  int watch_stdin; /* stdin is a pipe: EOF stops pong and sink */
  int spin;        /* BENCH_SPIN=1 */
  int type, role;
  char ping_channel[64], pong_channel[64], tput_channel[64];

  /* ping: the sequence number awaited and when it came */
  int64_t want;
  int got;
  uint64_t got_at;
  /* pong / sink */
  int stop;
  uint64_t received, first, last;
  int64_t max_seq;
  int publish_errors;
};

/* Payload bytes a message carries, as horus-dds-pingpong counts them for its MB/s. */
static uint64_t payload_bytes(int type) {
  return type == kCmdVel ? 16u : type == kKilobyte ? 1024u : (uint64_t)kImageBytes;
}

/* Common part of the three typed handlers; republish() is the typed publish of the pong. */
static void on_message(struct bench* b, int64_t seq, const void* msg) {
  switch (b->role) {
    case kPing:
      if (seq == b->want) {
        b->got = 1;
        b->got_at = now_ns();
      }
      break;
    case kPong:
      if (seq == kStopSeq) {
        b->stop = 1;
        break;
      }
      {
        int rc;
        if (b->type == kCmdVel)
          rc = horus_msg_CmdVel_publish(b->lcm, b->pong_channel, msg);
        else if (b->type == kKilobyte)
          rc = horus_bench_Kilobyte_publish(b->lcm, b->pong_channel, msg);
        else
          rc = horus_msg_Image_publish(b->lcm, b->pong_channel, msg);
        if (rc != 0) b->publish_errors++;
      }
      break;
    case kSink:
      if (seq == kStopSeq) {
        b->stop = 1;
        break;
      }
      b->last = now_ns();
      if (b->received++ == 0) b->first = b->last;
      if (seq > b->max_seq) b->max_seq = seq;
      break;
    default: break;
  }
}

static void on_cmdvel(const lcm_recv_buf_t* rb, const char* channel, const horus_msg_CmdVel* msg, void* user) {
  (void)rb;
  (void)channel;
  on_message(user, msg->stamp_nanos, msg);
}

static void on_kilobyte(const lcm_recv_buf_t* rb, const char* channel, const horus_bench_Kilobyte* msg, void* user) {
  (void)rb;
  (void)channel;
  on_message(user, msg->seq, msg);
}

static void on_image(const lcm_recv_buf_t* rb, const char* channel, const horus_msg_Image* msg, void* user) {
  (void)rb;
  (void)channel;
  on_message(user, msg->timestamp_ns, msg);
}

/* Typed subscription with an unlimited queue (the default of 30 drops silently). The channel is
 * a regex anchored by LCM: the dots are escaped so that it matches exactly this name. */
static int subscribe(struct bench* b, const char* channel) {
  char pattern[160];
  size_t k = 0;
  for (const char* c = channel; *c != '\0' && k + 3 < sizeof pattern; c++) {
    if (*c == '.') pattern[k++] = '\\';
    pattern[k++] = *c;
  }
  pattern[k] = '\0';
  int rc = -1;
  if (b->type == kCmdVel) {
    horus_msg_CmdVel_subscription_t* s = horus_msg_CmdVel_subscribe(b->lcm, pattern, on_cmdvel, b);
    if (s != NULL) rc = horus_msg_CmdVel_subscription_set_queue_capacity(s, 0);
  } else if (b->type == kKilobyte) {
    horus_bench_Kilobyte_subscription_t* s = horus_bench_Kilobyte_subscribe(b->lcm, pattern, on_kilobyte, b);
    if (s != NULL) rc = horus_bench_Kilobyte_subscription_set_queue_capacity(s, 0);
  } else {
    horus_msg_Image_subscription_t* s = horus_msg_Image_subscribe(b->lcm, pattern, on_image, b);
    if (s != NULL) rc = horus_msg_Image_subscription_set_queue_capacity(s, 0);
  }
  if (rc != 0) fprintf(stderr, "raw-lcm: subscribing to %s failed\n", channel);
  return rc == 0;
}

/* ---- the message sent: constant payload, prepared once ----------------------------------------- */

union sample {
  horus_msg_CmdVel cmdvel;
  horus_bench_Kilobyte kilobyte;
  horus_msg_Image image;
};

/* Fills the message the way horus's types encode: the Image as horus::msg::Image(1080, 1920,
 * Rgb8) reflects (width, height, encoding, step, frame_id, timestamp_ns, data). */
static int fill_out(int type, union sample* s) {
  memset(s, 0, sizeof *s);
  if (type == kCmdVel) {
    s->cmdvel.linear = 0.5f;
    s->cmdvel.angular = 0.25f;
  } else if (type == kKilobyte) {
    for (size_t i = 0; i < sizeof s->kilobyte.payload; i++) s->kilobyte.payload[i] = (uint8_t)i;
  } else {
    horus_msg_Image* img = &s->image;
    img->width = kImageWidth;
    img->height = kImageHeight;
    img->encoding = HORUS_MSG_IMAGEENCODING_Rgb8;
    img->step = kImageStep;
    memcpy(img->frame_id, "camera", 6);
    img->num_data = kImageBytes;
    img->data = malloc((size_t)kImageBytes);
    if (img->data == NULL) return 0;
    for (int32_t i = 0; i < kImageBytes; i++) img->data[i] = (uint8_t)i;
  }
  return 1;
}

static void set_seq(int type, union sample* s, int64_t seq) {
  if (type == kCmdVel)
    s->cmdvel.stamp_nanos = seq;
  else if (type == kKilobyte)
    s->kilobyte.seq = seq;
  else
    s->image.timestamp_ns = seq;
}

static int publish(struct bench* b, const char* channel, const union sample* s) {
  if (b->type == kCmdVel) return horus_msg_CmdVel_publish(b->lcm, channel, &s->cmdvel);
  if (b->type == kKilobyte) return horus_bench_Kilobyte_publish(b->lcm, channel, &s->kilobyte);
  return horus_msg_Image_publish(b->lcm, channel, &s->image);
}

/* ---- receiving: poll the LCM descriptor (and stdin), lcm_handle in this thread ----------------- */

/* Waits up to timeout_ms for one message and dispatches it. Returns 1 when a message was
 * handled, 0 on timeout, -1 on stdin EOF (when watched), -2 when LCM failed. */
static int pump(struct bench* b, int timeout_ms) {
  struct pollfd fds[2] = {{b->fd, POLLIN, 0}, {STDIN_FILENO, POLLIN, 0}};
  const nfds_t nfds = b->watch_stdin ? 2 : 1;
  const int n = poll(fds, nfds, b->spin ? 0 : timeout_ms);
  if (n < 0) return errno == EINTR ? 0 : -2;
  if (n == 0) {
    if (b->spin) sched_yield();
    return 0;
  }
  if (fds[0].revents & (POLLIN | POLLERR | POLLHUP)) {
    if (lcm_handle(b->lcm) != 0) {
      fprintf(stderr, "raw-lcm: lcm_handle failed\n");
      return -2;
    }
    return 1;
  }
  if (nfds == 2 && fds[1].revents != 0) {
    char buf[256];
    const ssize_t r = read(STDIN_FILENO, buf, sizeof buf);
    if (r == 0 || (r < 0 && errno != EINTR && errno != EAGAIN)) return -1;
  }
  return 0;
}

/* Milliseconds to the deadline for poll(), at most kIdlePollMs (so that deadlines are kept). */
static int ms_until(uint64_t deadline) {
  const uint64_t now = now_ns();
  if (now >= deadline) return 0;
  const uint64_t ms = (deadline - now + 999999u) / 1000000u;
  return ms > kIdlePollMs ? kIdlePollMs : (int)ms;
}

/* Only a pipe or socket is watched: /dev/null or a file would end at once, and reading a
 * terminal from a background job would stop the process (SIGTTIN). */
static int stdin_is_pipe(void) {
  struct stat st;
  if (fstat(STDIN_FILENO, &st) != 0) return 0;
  return S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode);
}

/* ---- pong / sink: handle until the stop marker, <seconds> or stdin EOF ------------------------- */

static int serve(struct bench* b, double seconds) {
  printf("ready\n");
  fflush(stdout);
  const uint64_t end = now_ns() + (uint64_t)(seconds * 1e9);
  while (!b->stop && now_ns() < end) {
    const int r = pump(b, ms_until(end));
    if (r < 0) break;
  }
  return 0;
}

static int run_pong(struct bench* b, double seconds) {
  if (!subscribe(b, b->ping_channel)) return 3;
  serve(b, seconds);
  if (b->publish_errors > 0) fprintf(stderr, "raw-lcm: pong: %d publish errors\n", b->publish_errors);
  return 0;
}

static int run_sink(struct bench* b, const char* type_name, double seconds) {
  if (!subscribe(b, b->tput_channel)) return 3;
  serve(b, seconds);
  const double s = (double)(b->last - b->first) / 1e9;
  const uint64_t lost = b->max_seq > 0 && (uint64_t)b->max_seq > b->received ? (uint64_t)b->max_seq - b->received : 0;
  printf("RESULT impl=%s type=%s mode=tput received=%" PRIu64 " seconds=%.3f rate=%.0f mbps=%.1f lost=%" PRIu64 "\n",
         kImpl, type_name, b->received, s, s > 0 ? (double)b->received / s : 0.0,
         s > 0 ? (double)(b->received * payload_bytes(b->type)) / s / 1e6 : 0.0, lost);
  fflush(stdout);
  return b->received > 0 ? 0 : 1;
}

/* ---- ping -------------------------------------------------------------------------------------- */

/* Publishes seq on the ping channel and handles messages until the pong sends it back (older
 * answers are skipped) or timeout_ns passes. Returns the RTT in ns, 0 when lost, UINT64_MAX
 * when LCM failed. */
static uint64_t round_trip(struct bench* b, union sample* out, int64_t seq, uint64_t timeout_ns) {
  set_seq(b->type, out, seq);
  b->want = seq;
  b->got = 0;
  const uint64_t t0 = now_ns();
  if (publish(b, b->ping_channel, out) != 0) b->publish_errors++;
  const uint64_t deadline = t0 + timeout_ns;
  while (!b->got) {
    if (now_ns() >= deadline) return 0;
    if (pump(b, ms_until(deadline)) == -2) return UINT64_MAX;
  }
  return b->got_at > t0 ? b->got_at - t0 : 1;
}

static int cmp_u64(const void* x, const void* y) {
  const uint64_t a = *(const uint64_t*)x, c = *(const uint64_t*)y;
  return a < c ? -1 : a > c;
}

/* As horus-dds-pingpong ranks: the element at index floor(q * n) of the sorted values. */
static uint64_t rank(const uint64_t* sorted, uint64_t n, double q) {
  if (n == 0) return 0;
  uint64_t k = (uint64_t)(q * (double)n);
  return sorted[k < n ? k : n - 1];
}

static int run_ping(struct bench* b, const char* type_name, uint64_t round_trips, uint64_t warmup) {
  union sample out;
  uint64_t* one_way = malloc((round_trips ? round_trips : 1) * sizeof(uint64_t));
  if (one_way == NULL || !fill_out(b->type, &out)) {
    fprintf(stderr, "raw-lcm: out of memory\n");
    return 3;
  }
  if (!subscribe(b, b->pong_channel)) return 3;
  const uint64_t timeout = b->type == kImage ? 2000000000ull : 1000000000ull;

  /* LCM has no discovery: probe until the pong answers. */
  int64_t seq = 0;
  const uint64_t match_deadline = now_ns() + kMatchDeadlineNs;
  for (;;) {
    const uint64_t r = round_trip(b, &out, ++seq, kProbeEveryNs);
    if (r == UINT64_MAX) return 3;
    if (r != 0) break;
    if (now_ns() >= match_deadline) {
      fprintf(stderr, "raw-lcm: no pong answered on %s / %s within 30 s\n", b->ping_channel, b->pong_channel);
      return 3;
    }
  }
  sleep_ms(50); /* let late answers to earlier probes arrive; they are skipped */

  for (uint64_t i = 0; i < warmup; i++)
    if (round_trip(b, &out, ++seq, timeout) == UINT64_MAX) return 3;
  uint64_t got = 0, lost = 0;
  long double sum = 0;
  for (uint64_t i = 0; i < round_trips; i++) {
    const uint64_t r = round_trip(b, &out, ++seq, timeout);
    if (r == UINT64_MAX) return 3;
    if (r == 0) {
      lost++;
      continue;
    }
    one_way[got++] = r / 2;
    sum += (long double)r / 2.0L;
  }

  /* Stop the pong (best effort: several times; it also stops at EOF on its stdin). */
  set_seq(b->type, &out, kStopSeq);
  for (int i = 0; i < 3; i++) {
    publish(b, b->ping_channel, &out);
    sleep_ms(20);
  }
  sleep_ms(50);

  if (got == 0) {
    printf("RESULT impl=%s type=%s n=0 lost=%" PRIu64 "\n", kImpl, type_name, lost);
    fflush(stdout);
    return 1;
  }
  qsort(one_way, got, sizeof *one_way, cmp_u64);
  printf("RESULT impl=%s type=%s n=%" PRIu64 " p50_ns=%" PRIu64 " p99_ns=%" PRIu64 " p999_ns=%" PRIu64 " mean_ns=%.0f",
         kImpl, type_name, got, rank(one_way, got, 0.5), rank(one_way, got, 0.99), rank(one_way, got, 0.999),
         (double)(sum / (long double)got));
  if (lost > 0) printf(" lost=%" PRIu64, lost);
  printf("\n");
  fflush(stdout);
  if (b->publish_errors > 0) fprintf(stderr, "raw-lcm: ping: %d publish errors\n", b->publish_errors);
  if (b->type == kImage) free(out.image.data);
  free(one_way);
  return 0;
}

/* ---- source ------------------------------------------------------------------------------------ */

static int run_source(struct bench* b, const char* type_name, double seconds) {
  union sample out;
  if (!fill_out(b->type, &out)) {
    fprintf(stderr, "raw-lcm: out of memory\n");
    return 3;
  }
  sleep_ms(200);
  const uint64_t t0 = now_ns(), end = t0 + (uint64_t)(seconds * 1e9);
  int64_t seq = 0;
  uint64_t t1 = t0;
  while ((t1 = now_ns()) < end) {
    set_seq(b->type, &out, ++seq);
    if (publish(b, b->tput_channel, &out) != 0) b->publish_errors++;
  }
  set_seq(b->type, &out, kStopSeq);
  for (int i = 0; i < 5; i++) {
    sleep_ms(30);
    publish(b, b->tput_channel, &out);
  }
  const double s = (double)(t1 - t0) / 1e9;
  printf("SENT impl=%s type=%s sent=%" PRId64 " seconds=%.3f rate=%.0f publish_errors=%d\n", kImpl, type_name, seq, s,
         s > 0 ? (double)seq / s : 0.0, b->publish_errors);
  fflush(stdout);
  if (b->type == kImage) free(out.image.data);
  return 0;
}

int main(int argc, char** argv) {
  if (argc < 2) return usage();
  const int role = strcmp(argv[1], "ping") == 0     ? kPing
                   : strcmp(argv[1], "pong") == 0   ? kPong
                   : strcmp(argv[1], "sink") == 0   ? kSink
                   : strcmp(argv[1], "source") == 0 ? kSource
                                                    : -1;
  if (role < 0 || argc != (role == kPing ? 6 : 5)) return usage();
  uint64_t n = 0, warmup = 0;
  double seconds = 0;
  if (role == kPing ? !parse_u64(argv[4], &n) || !parse_u64(argv[5], &warmup) : !parse_seconds(argv[4], &seconds))
    return usage();
  int type;
  if (strcmp(argv[3], "cmdvel") == 0)
    type = kCmdVel;
  else if (strcmp(argv[3], "kilobyte") == 0)
    type = kKilobyte;
  else if (strcmp(argv[3], "image") == 0)
    type = kImage;
  else
    return usage();

  static struct bench b; /* zeroed */
  b.type = type;
  b.role = role;
  const char* spin = getenv("BENCH_SPIN");
  b.spin = spin != NULL && spin[0] != '\0' && strcmp(spin, "0") != 0;
  b.watch_stdin = (role == kPong || role == kSink) && stdin_is_pipe();
  snprintf(b.ping_channel, sizeof b.ping_channel, "bench.%s.ping", argv[3]);
  snprintf(b.pong_channel, sizeof b.pong_channel, "bench.%s.pong", argv[3]);
  snprintf(b.tput_channel, sizeof b.tput_channel, "bench.%s.tput", argv[3]);

  const char* url = getenv("HORUS_LCM_URL");
  if (url != NULL && url[0] == '\0') url = NULL;
  b.lcm = lcm_create(url);
  if (b.lcm == NULL) {
    fprintf(stderr, "raw-lcm: lcm_create(%s) failed (liblcm printed the reason above)\n", url ? url : "default URL");
    return 3;
  }
  /* On udpm this opens the receive socket and starts LCM's reader thread: do it now. A source
   * only publishes, as a plain LCM publisher does: it opens no receive socket, and so does not
   * receive (and reassemble) its own messages from the multicast loopback. */
  b.fd = role == kSource ? 0 : lcm_get_fileno(b.lcm);
  if (b.fd < 0) {
    fprintf(stderr, "raw-lcm: LCM receive setup failed for %s\n", url ? url : "the default URL");
    lcm_destroy(b.lcm);
    return 3;
  }

  int rc;
  if (role == kPing)
    rc = run_ping(&b, argv[3], n, warmup);
  else if (role == kPong)
    rc = run_pong(&b, seconds);
  else if (role == kSink)
    rc = run_sink(&b, argv[3], seconds);
  else
    rc = run_source(&b, argv[3], seconds);
  lcm_destroy(b.lcm);
  return rc;
}
