/* raw_cyclone_pingpong: the raw Cyclone DDS baseline of the DDS latency benchmark. A plain
 * Cyclone DDS C program over what idlc generates from horus's .idl files (geometry.idl,
 * vision.idl, horus_bench.idl); no horus code. Its twin is raw_fastdds_pingpong.cpp: same
 * command line, topics, QoS and loop, so the two (and horus) are compared like for like.
 *
 *   raw-cyclone-pingpong pong <domain> <type> <seconds>
 *   raw-cyclone-pingpong ping <domain> <type> <round_trips> <warmup>
 *   raw-cyclone-pingpong sink <domain> <type> <seconds>      throughput: counts what arrives on
 *   raw-cyclone-pingpong source <domain> <type> <seconds>    horus/bench/<type>/tput, sent back to back
 *     type: cmdvel | kilobyte | image   (image: 1920x1080 RGB8, 6,220,800 bytes of data)
 *
 * pong takes every sample of horus/bench/<type>/ping and writes that same sample back on
 * horus/bench/<type>/pong. It prints "ready" once its endpoints exist and stops after
 * <seconds>, when its stdin (a pipe) reaches EOF, or on a sample whose seq is UINT64_MAX.
 * ping waits for both matches (30 s), runs <warmup> then <round_trips> round trips, stops the
 * pong and prints one line:
 *   RESULT impl=raw-cyclone type=<type> n=<round_trips> p50_ns= p99_ns= p999_ns= mean_ns= [lost=<k>]
 * with the one-way latency (RTT/2). A round trip with no answer within 2 s is lost.
 *
 * sink prints "ready", counts the samples of horus/bench/<type>/tput until one whose seq is
 * UINT64_MAX (or <seconds>, or EOF on its stdin pipe), and prints
 *   RESULT impl=raw-cyclone type=<type> mode=tput received=<n> seconds=<s> rate=<msgs/s> mbps=<MB/s> lost=<gaps> qos=<history> wait=..
 * timed from the first to the last counted sample; MB are payload bytes (cmdvel 16, kilobyte
 * 1024, image 6,220,800 a sample), as horus-dds-pingpong counts them. source waits for a
 * matched reader (30 s), writes back to back for <seconds>, then the stop sample 3 times.
 *
 * Receiving: a waitset on a read condition by default; BENCH_POLL=1: dds_take in a loop with
 * sched_yield() between empty takes, as horus-dds-pingpong receives (its recv() does not block).
 * Both RESULT lines end in wait=waitset or wait=poll.
 *
 * UDP only (no shared memory); BENCH_LOCALHOST=1: loopback only, unicast discovery.
 * Exit: 0 ok, 2 usage, 3 setup failure. */
#define _GNU_SOURCE
#include <errno.h>
#include <inttypes.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <dds/dds.h>

#include "geometry.h"
#include "horus_bench.h"
#include "vision.h"

enum { kCmdVel, kKilobyte, kImage };
enum { kPing, kPong, kSink, kSource };
enum { kImageWidth = 1920, kImageHeight = 1080, kImageStep = kImageWidth * 3 };
#define kImageBytes ((uint32_t)kImageStep * kImageHeight)
#define kStopSeq UINT64_MAX
#define kLostAfterNs 2000000000ull
#define kMatchDeadlineNs 30000000000ull

static const char* kLocalhostXml =
    "<CycloneDDS><Domain Id=\"any\"><General>"
    "<Interfaces><NetworkInterface address=\"127.0.0.1\" multicast=\"false\"/></Interfaces>"
    "<AllowMulticast>false</AllowMulticast></General>"
    "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>"
    "<Peers><Peer Address=\"127.0.0.1\"/></Peers></Discovery>"
    "<Internal><SocketReceiveBufferSize min=\"default\" max=\"8MiB\"/>"
    "<SocketSendBufferSize min=\"64KiB\" max=\"4MiB\"/></Internal>"
    "<SharedMemory><Enable>false</Enable></SharedMemory>"
    "</Domain></CycloneDDS>";

static const char* kLanXml =
    "<CycloneDDS><Domain Id=\"any\">"
    "<Internal><SocketReceiveBufferSize min=\"default\" max=\"8MiB\"/>"
    "<SocketSendBufferSize min=\"64KiB\" max=\"4MiB\"/></Internal>"
    "<SharedMemory><Enable>false</Enable></SharedMemory>"
    "</Domain></CycloneDDS>";

/* BENCH_POLL=1: receive by polling dds_take (sched_yield() between empty takes), no waitset. */
static int g_poll;

static uint64_t now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static int usage(void) {
  fprintf(stderr,
          "usage: raw-cyclone-pingpong pong <domain> <type> <seconds>\n"
          "       raw-cyclone-pingpong ping <domain> <type> <round_trips> <warmup>\n"
          "       raw-cyclone-pingpong sink <domain> <type> <seconds>\n"
          "       raw-cyclone-pingpong source <domain> <type> <seconds>\n"
          "  type: cmdvel | kilobyte | image\n"
          "  BENCH_LOCALHOST=1: loopback only; BENCH_POLL=1: receive by polling, not a waitset\n");
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

/* The sequence-number field of each type (the stop signal is UINT64_MAX there). */
static uint64_t* seq_field(int type, void* sample) {
  switch (type) {
    case kCmdVel: return &((horus_msg_CmdVel*)sample)->stamp_nanos;
    case kKilobyte: return &((horus_bench_Kilobyte*)sample)->seq;
    default: return &((horus_msg_Image*)sample)->timestamp_ns;
  }
}

/* A zeroed sample the reader deserializes into (an Image's sequence grows once, then is reused). */
static void* alloc_sample(int type) {
  switch (type) {
    case kCmdVel: return calloc(1, sizeof(horus_msg_CmdVel));
    case kKilobyte: return calloc(1, sizeof(horus_bench_Kilobyte));
    default: return calloc(1, sizeof(horus_msg_Image));
  }
}

static const dds_topic_descriptor_t* descriptor(int type) {
  return type == kCmdVel ? &horus_msg_CmdVel_desc : type == kKilobyte ? &horus_bench_Kilobyte_desc : &horus_msg_Image_desc;
}

/* Payload bytes a sample carries, as horus-dds-pingpong counts them for its MB/s. */
static uint64_t payload_bytes(int type) {
  return type == kCmdVel ? 16u : type == kKilobyte ? 1024u : (uint64_t)kImageBytes;
}

/* The constant payload of a written sample, prepared once (the image buffer is ours, not
 * released by Cyclone; free_out releases it). Returns 0 when out of memory. */
static int fill_out(int type, void* out) {
  if (type == kCmdVel) {
    ((horus_msg_CmdVel*)out)->linear = 0.5f;
    ((horus_msg_CmdVel*)out)->angular = -0.25f;
  } else if (type == kKilobyte) {
    horus_bench_Kilobyte* k = out;
    for (size_t i = 0; i < sizeof k->payload; i++) k->payload[i] = (uint8_t)i;
  } else {
    horus_msg_Image* img = out;
    img->width = kImageWidth;
    img->height = kImageHeight;
    img->encoding = horus_msg_ImageEncoding_Rgb8;
    img->step = kImageStep;
    strcpy(img->frame_id, "camera");
    img->data._buffer = malloc(kImageBytes);
    if (img->data._buffer == NULL) return 0;
    for (uint32_t i = 0; i < kImageBytes; i++) img->data._buffer[i] = (uint8_t)(i * 7u);
    img->data._length = img->data._maximum = kImageBytes;
    img->data._release = false;
  }
  return 1;
}

static void free_out(int type, void* out) {
  if (out == NULL) return;
  if (type == kImage) free(((horus_msg_Image*)out)->data._buffer);
  free(out);
}

/* ---- stdin watcher: a guard condition raised when the parent closes our stdin pipe ---------- */

static dds_entity_t g_stdin_guard;
static atomic_int g_stdin_eof; /* the same news for a polling loop */

static void* stdin_watch(void* arg) {
  (void)arg;
  char buf[256];
  for (;;) {
    ssize_t n = read(STDIN_FILENO, buf, sizeof buf);
    if (n > 0) continue;
    if (n < 0 && errno == EINTR) continue;
    break; /* EOF or error: the parent is gone */
  }
  atomic_store(&g_stdin_eof, 1);
  if (g_stdin_guard > 0) dds_set_guardcondition(g_stdin_guard, true);
  return NULL;
}

/* Only a pipe or socket is watched: /dev/null or a file would end at once, and reading a
 * terminal from a background job would stop the process (SIGTTIN). */
static int stdin_is_pipe(void) {
  struct stat st;
  if (fstat(STDIN_FILENO, &st) != 0) return 0;
  return S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode);
}

/* Watches stdin (when a pipe) from a detached thread; the guard, when the waitset exists. */
static int watch_stdin(dds_entity_t participant, dds_entity_t waitset) {
  if (waitset > 0) {
    g_stdin_guard = dds_create_guardcondition(participant);
    if (g_stdin_guard < 0 || dds_waitset_attach(waitset, g_stdin_guard, g_stdin_guard) < 0) {
      fprintf(stderr, "raw-cyclone: creating the guard condition\n");
      return 0;
    }
  }
  if (stdin_is_pipe()) {
    pthread_t th;
    if (pthread_create(&th, NULL, stdin_watch, NULL) == 0) pthread_detach(th);
  }
  return 1;
}

/* ---- setup ---------------------------------------------------------------------------------- */

struct endpoints {
  dds_entity_t domain, participant, writer, reader, waitset, readcond;
};

/* ping: writer on .../ping, reader on .../pong; pong the reverse; sink: a reader on .../tput;
 * source: a writer on .../tput. The waitset (and read condition) only when waiting on one. */
/* BENCH_KEEP_ALL=1: the QoS of horus's reliable fleet topics (KEEP_ALL within the reader's 4096
   samples), for a throughput comparison on equal terms; else KEEP_LAST 16. */
static int keep_all_from_env(void) {
  const char* v = getenv("BENCH_KEEP_ALL");
  return v != NULL && strcmp(v, "1") == 0;
}

static int setup(struct endpoints* ep, uint32_t domain_id, int type, const char* type_name, int role) {
  const char* env = getenv("BENCH_LOCALHOST");
  const int localhost = env != NULL && env[0] != '\0' && strcmp(env, "0") != 0;
  const dds_topic_descriptor_t* desc = descriptor(type);
  char ping_name[64], pong_name[64];
  const int tput = role == kSink || role == kSource;
  snprintf(ping_name, sizeof ping_name, "horus/bench/%s/%s", type_name, tput ? "tput" : "ping");
  snprintf(pong_name, sizeof pong_name, "horus/bench/%s/pong", type_name);

  memset(ep, 0, sizeof *ep);
  /* CYCLONEDDS_URI, when set, is merged after this configuration, as Cyclone merges a list of
   * configurations: how a Cyclone user adds DDS-Security (run_dds_bench.sh --secure gives the
   * document `horus security dds-config --for cyclonedds` writes). */
  const char* xml = localhost ? kLocalhostXml : kLanXml;
  const char* more = getenv("CYCLONEDDS_URI");
  char* merged = NULL;
  if (more != NULL && more[0] != '\0') {
    const size_t n = strlen(xml) + strlen(more) + 2;
    merged = malloc(n);
    if (merged == NULL) return 0;
    snprintf(merged, n, "%s,%s", xml, more);
    xml = merged;
  }
  ep->domain = dds_create_domain((dds_domainid_t)domain_id, xml);
  free(merged);
  if (ep->domain < 0) {
    fprintf(stderr, "raw-cyclone: dds_create_domain(%u): %s\n", domain_id, dds_strretcode(ep->domain));
    return 0;
  }
  ep->participant = dds_create_participant((dds_domainid_t)domain_id, NULL, NULL);
  if (ep->participant < 0) {
    fprintf(stderr, "raw-cyclone: dds_create_participant: %s\n", dds_strretcode(ep->participant));
    return 0;
  }
  /* sink/source: ping_topic is .../tput and there is no pong topic. */
  dds_entity_t ping_topic = dds_create_topic(ep->participant, desc, ping_name, NULL, NULL);
  dds_entity_t pong_topic = tput ? ping_topic : dds_create_topic(ep->participant, desc, pong_name, NULL, NULL);
  if (ping_topic < 0 || pong_topic < 0) {
    fprintf(stderr, "raw-cyclone: dds_create_topic: %s\n", dds_strretcode(ping_topic < 0 ? ping_topic : pong_topic));
    return 0;
  }

  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  if (keep_all_from_env()) {
    /* horus's reliable fleet topics on Cyclone (backend_dds/src/cyclone_endpoint.cpp): KEEP_ALL,
       a reader holds at most 4096 samples not yet taken. */
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    dds_qset_resource_limits(qos, 4096, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  } else {
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 16);
  }
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos, 1, &xcdr1);
  if (role != kSource) ep->reader = dds_create_reader(ep->participant, role == kPing ? pong_topic : ping_topic, qos, NULL);
  if (role != kSink) ep->writer = dds_create_writer(ep->participant, role == kPong ? pong_topic : ping_topic, qos, NULL);
  dds_delete_qos(qos);
  if (ep->reader < 0 || ep->writer < 0) {
    fprintf(stderr, "raw-cyclone: creating the reader/writer: %s\n",
            dds_strretcode(ep->reader < 0 ? ep->reader : ep->writer));
    return 0;
  }

  if (role == kSource || g_poll) return 1;
  ep->waitset = dds_create_waitset(ep->participant);
  ep->readcond = dds_create_readcondition(ep->reader, DDS_ANY_STATE);
  if (ep->waitset < 0 || ep->readcond < 0 || dds_waitset_attach(ep->waitset, ep->readcond, ep->readcond) < 0) {
    fprintf(stderr, "raw-cyclone: creating the waitset\n");
    return 0;
  }
  return 1;
}

/* ---- pong ----------------------------------------------------------------------------------- */

static int run_pong(struct endpoints* ep, int type, uint64_t seconds) {
  if (!watch_stdin(ep->participant, ep->waitset)) return 3;
  void* sample = alloc_sample(type);
  void* buf[1] = {sample};
  dds_sample_info_t info;
  printf("ready\n");
  fflush(stdout);

  const uint64_t end = now_ns() + seconds * 1000000000ull;
  int stop = 0;
  while (g_poll && !stop) {
    if (dds_take(ep->reader, buf, &info, 1, 1) > 0) {
      if (!info.valid_data) continue;
      if (*seq_field(type, sample) == kStopSeq) break;
      dds_write(ep->writer, sample);
      continue;
    }
    if (now_ns() >= end || atomic_load_explicit(&g_stdin_eof, memory_order_relaxed)) break;
    sched_yield();
  }
  while (!g_poll && !stop) {
    const uint64_t now = now_ns();
    if (now >= end) break;
    dds_attach_t xs[2];
    const dds_return_t n = dds_waitset_wait(ep->waitset, xs, 2, (dds_duration_t)(end - now));
    for (dds_return_t i = 0; i < n; i++)
      if (xs[i] == (dds_attach_t)g_stdin_guard) stop = 1;
    while (!stop && dds_take(ep->reader, buf, &info, 1, 1) > 0) {
      if (!info.valid_data) continue;
      if (*seq_field(type, sample) == kStopSeq) {
        stop = 1;
        break;
      }
      dds_write(ep->writer, sample);
    }
  }
  dds_sample_free(sample, descriptor(type), DDS_FREE_ALL);
  return 0;
}

/* ---- ping ----------------------------------------------------------------------------------- */

static int wait_matched(struct endpoints* ep) {
  const uint64_t deadline = now_ns() + kMatchDeadlineNs;
  for (;;) {
    dds_publication_matched_status_t pm;
    dds_subscription_matched_status_t sm;
    if (dds_get_publication_matched_status(ep->writer, &pm) == 0 &&
        dds_get_subscription_matched_status(ep->reader, &sm) == 0 && pm.current_count > 0 && sm.current_count > 0)
      return 1;
    if (now_ns() >= deadline) return 0;
    dds_sleepfor(DDS_MSECS(10));
  }
}

/* One round trip: write seq, wait for the pong sample with that seq (older ones are skipped).
 * Returns the RTT in ns, or 0 when nothing came back within 2 s. */
static uint64_t round_trip(struct endpoints* ep, int type, void* out, void* in, uint64_t seq) {
  void* buf[1] = {in};
  dds_sample_info_t info;
  *seq_field(type, out) = seq;
  const uint64_t t0 = now_ns();
  dds_write(ep->writer, out);
  const uint64_t deadline = t0 + kLostAfterNs;
  for (;;) {
    while (dds_take(ep->reader, buf, &info, 1, 1) > 0) {
      if (info.valid_data && *seq_field(type, in) == seq) return now_ns() - t0;
    }
    const uint64_t now = now_ns();
    if (now >= deadline) return 0;
    if (g_poll)
      sched_yield();
    else
      dds_waitset_wait(ep->waitset, NULL, 0, (dds_duration_t)(deadline - now));
  }
}

static int cmp_u64(const void* a, const void* b) {
  const uint64_t x = *(const uint64_t*)a, y = *(const uint64_t*)b;
  return x < y ? -1 : x > y;
}

/* Nearest rank: the ceil(p * n)-th smallest. */
static uint64_t percentile(const uint64_t* sorted, uint64_t n, double p) {
  if (n == 0) return 0;
  uint64_t rank = (uint64_t)(p * (double)n);
  if ((double)rank < p * (double)n) rank++;
  if (rank < 1) rank = 1;
  if (rank > n) rank = n;
  return sorted[rank - 1];
}

static int run_ping(struct endpoints* ep, int type, const char* type_name, uint64_t round_trips, uint64_t warmup) {
  void* out = alloc_sample(type);
  void* in = alloc_sample(type);
  uint64_t* rtt = malloc((round_trips ? round_trips : 1) * sizeof(uint64_t));
  if (out == NULL || in == NULL || rtt == NULL) {
    fprintf(stderr, "raw-cyclone: out of memory\n");
    return 3;
  }
  /* The payload: constant, prepared once. */
  if (!fill_out(type, out)) {
    fprintf(stderr, "raw-cyclone: out of memory\n");
    return 3;
  }

  if (!wait_matched(ep)) {
    fprintf(stderr, "raw-cyclone: no pong matched on horus/bench/%s/{ping,pong} within 30 s\n", type_name);
    return 3;
  }

  uint64_t seq = 0;
  for (uint64_t i = 0; i < warmup; i++) (void)round_trip(ep, type, out, in, seq++);
  uint64_t got = 0, lost = 0;
  for (uint64_t i = 0; i < round_trips; i++) {
    const uint64_t r = round_trip(ep, type, out, in, seq++);
    if (r == 0)
      lost++;
    else
      rtt[got++] = r;
  }

  /* Stop the pong; let the sample be acknowledged before the domain goes. */
  *seq_field(type, out) = kStopSeq;
  dds_write(ep->writer, out);
  dds_wait_for_acks(ep->writer, DDS_SECS(2));

  qsort(rtt, got, sizeof *rtt, cmp_u64);
  long double sum = 0;
  for (uint64_t i = 0; i < got; i++) sum += (long double)rtt[i];
  const uint64_t mean = got ? (uint64_t)(sum / (long double)got / 2.0L + 0.5L) : 0;
  printf("RESULT impl=raw-cyclone type=%s n=%" PRIu64 " p50_ns=%" PRIu64 " p99_ns=%" PRIu64 " p999_ns=%" PRIu64
         " mean_ns=%" PRIu64,
         type_name, round_trips, percentile(rtt, got, 0.50) / 2, percentile(rtt, got, 0.99) / 2,
         percentile(rtt, got, 0.999) / 2, mean);
  if (lost > 0) printf(" lost=%" PRIu64, lost);
  printf(" wait=%s\n", g_poll ? "poll" : "waitset");
  fflush(stdout);

  free_out(type, out);
  dds_sample_free(in, descriptor(type), DDS_FREE_ALL);
  free(rtt);
  return 0;
}

/* ---- sink / source (throughput) ------------------------------------------------------------- */

/* The sink's loss accounting, as horus's sink reports its dropped count: the sequence numbers
   between the first and the last sample received that never came (the source numbers them 1, 2, ...). */
struct seq_gaps {
  uint64_t lo, hi;
};
static void gaps_add(struct seq_gaps* g, uint64_t seq) {
  if (seq < g->lo) g->lo = seq;
  if (seq > g->hi) g->hi = seq;
}
static uint64_t gaps_lost(const struct seq_gaps* g, uint64_t received) {
  return received == 0 || g->hi - g->lo + 1 < received ? 0 : g->hi - g->lo + 1 - received;
}

static int run_sink(struct endpoints* ep, int type, const char* type_name, uint64_t seconds) {
  if (!watch_stdin(ep->participant, ep->waitset)) return 3;
  void* sample = alloc_sample(type);
  if (sample == NULL) {
    fprintf(stderr, "raw-cyclone: out of memory\n");
    return 3;
  }
  void* buf[1] = {sample};
  dds_sample_info_t info;
  printf("ready\n");
  fflush(stdout);

  const uint64_t end = now_ns() + seconds * 1000000000ull;
  uint64_t received = 0, first = 0, last = 0;
  struct seq_gaps gaps = {UINT64_MAX, 0};
  while (g_poll) {
    if (dds_take(ep->reader, buf, &info, 1, 1) > 0) {
      if (!info.valid_data) continue;
      if (*seq_field(type, sample) == kStopSeq) break;
      gaps_add(&gaps, *seq_field(type, sample));
      last = now_ns();
      if (received++ == 0) first = last;
      continue;
    }
    if (now_ns() >= end || atomic_load_explicit(&g_stdin_eof, memory_order_relaxed)) break;
    sched_yield();
  }
  int stop = 0;
  while (!g_poll && !stop) {
    const uint64_t now = now_ns();
    if (now >= end) break;
    dds_attach_t xs[2];
    const dds_return_t n = dds_waitset_wait(ep->waitset, xs, 2, (dds_duration_t)(end - now));
    for (dds_return_t i = 0; i < n; i++)
      if (xs[i] == (dds_attach_t)g_stdin_guard) stop = 1;
    while (!stop && dds_take(ep->reader, buf, &info, 1, 1) > 0) {
      if (!info.valid_data) continue;
      if (*seq_field(type, sample) == kStopSeq) {
        stop = 1;
        break;
      }
      gaps_add(&gaps, *seq_field(type, sample));
      last = now_ns();
      if (received++ == 0) first = last;
    }
  }
  dds_sample_free(sample, descriptor(type), DDS_FREE_ALL);

  const double s = (double)(last - first) / 1e9;
  printf("RESULT impl=raw-cyclone type=%s mode=tput received=%" PRIu64
         " seconds=%.3f rate=%.0f mbps=%.1f lost=%" PRIu64 " qos=%s wait=%s\n",
         type_name, received, s, s > 0 ? (double)received / s : 0.0,
         s > 0 ? (double)(received * payload_bytes(type)) / s / 1e6 : 0.0, gaps_lost(&gaps, received),
         keep_all_from_env() ? "keep_all4096" : "keep_last16", g_poll ? "poll" : "waitset");
  fflush(stdout);
  return received > 0 ? 0 : 1;
}

static int run_source(struct endpoints* ep, int type, const char* type_name, uint64_t seconds) {
  void* out = alloc_sample(type);
  if (out == NULL || !fill_out(type, out)) {
    fprintf(stderr, "raw-cyclone: out of memory\n");
    return 3;
  }
  const uint64_t deadline = now_ns() + kMatchDeadlineNs;
  for (;;) {
    dds_publication_matched_status_t pm;
    if (dds_get_publication_matched_status(ep->writer, &pm) == 0 && pm.current_count > 0) break;
    if (now_ns() >= deadline) {
      fprintf(stderr, "raw-cyclone: no sink matched on horus/bench/%s/tput within 30 s\n", type_name);
      free_out(type, out);
      return 3;
    }
    dds_sleepfor(DDS_MSECS(10));
  }
  dds_sleepfor(DDS_MSECS(200));

  const uint64_t end = now_ns() + seconds * 1000000000ull;
  for (uint64_t seq = 1; now_ns() < end; seq++) {
    *seq_field(type, out) = seq;
    dds_write(ep->writer, out);
  }
  *seq_field(type, out) = kStopSeq;
  for (int i = 0; i < 3; i++) {
    dds_write(ep->writer, out);
    dds_sleepfor(DDS_MSECS(50));
  }
  dds_wait_for_acks(ep->writer, DDS_SECS(2));
  free_out(type, out);
  return 0;
}

int main(int argc, char** argv) {
  if (argc < 2) return usage();
  const int role = strcmp(argv[1], "ping") == 0     ? kPing
                   : strcmp(argv[1], "pong") == 0   ? kPong
                   : strcmp(argv[1], "sink") == 0   ? kSink
                   : strcmp(argv[1], "source") == 0 ? kSource
                                                    : -1;
  const int is_ping = role == kPing;
  if (role < 0 || argc != (is_ping ? 6 : 5)) return usage();
  const char* poll_env = getenv("BENCH_POLL");
  g_poll = poll_env != NULL && poll_env[0] != '\0' && strcmp(poll_env, "0") != 0;
  uint64_t domain = 0, a = 0, b = 0;
  if (!parse_u64(argv[2], &domain) || domain > 232 || !parse_u64(argv[4], &a) || (is_ping && !parse_u64(argv[5], &b)))
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

  struct endpoints ep;
  int rc;
  if (!setup(&ep, (uint32_t)domain, type, argv[3], role))
    rc = 3;
  else if (role == kPing)
    rc = run_ping(&ep, type, argv[3], a, b);
  else if (role == kPong)
    rc = run_pong(&ep, type, a);
  else if (role == kSink)
    rc = run_sink(&ep, type, argv[3], a);
  else
    rc = run_source(&ep, type, argv[3], a);
  if (ep.domain > 0) dds_delete(ep.domain);
  return rc;
}
