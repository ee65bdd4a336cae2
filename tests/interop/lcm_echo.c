/* lcm_echo: a plain C LCM program, built at test time from the code `lcm-gen -c` writes for
 * horus-idlgen's .lcm files (tests/interop/build_peers.cmake); no horus code.
 *
 *   lcm_echo <prefix> <seconds>        (URL: HORUS_LCM_URL, else LCM's default)
 *
 * Every message on <prefix>.<Type> (Type one of the generated types) is decoded with the
 * generated <pkg>_<Type>_decode (which checks the fingerprint), encoded again with
 * <pkg>_<Type>_encode, and published on <prefix>.<Type>.echo: horus -> lcm-gen code -> horus.
 * A message that does not decode, or leaves bytes over, is reported on stderr and not echoed.
 * Prints "ready" once subscribed; exits when stdin closes or after <seconds>. */
#include <lcm/lcm.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "lcm_echo_headers.h" /* generated: #include "<pkg>_<Type>.h" for every type */

static lcm_t *lcm;
static int failures;

/* One echo function per type. */
#define HORUS_LCM_TYPE(pkg, T)                                                        \
  static int echo_##pkg##_##T(const lcm_recv_buf_t *rb, const char *out) {            \
    pkg##_##T m;                                                                      \
    int used = pkg##_##T##_decode(rb->data, 0, (int)rb->data_size, &m);               \
    if (used < 0) return -1;                                                          \
    int rc = -2;                                                                      \
    if ((unsigned)used == rb->data_size) {                                            \
      int n = pkg##_##T##_encoded_size(&m);                                           \
      void *buf = malloc((size_t)n);                                                  \
      rc = pkg##_##T##_encode(buf, 0, n, &m) == n ? lcm_publish(lcm, out, buf, (unsigned)n) : -3; \
      free(buf);                                                                      \
    }                                                                                 \
    pkg##_##T##_decode_cleanup(&m);                                                   \
    return rc;                                                                        \
  }
#include "lcm_echo_types.inc"
#undef HORUS_LCM_TYPE

struct entry {
  const char *name;
  int (*echo)(const lcm_recv_buf_t *, const char *);
};
#define HORUS_LCM_TYPE(pkg, T) {#T, echo_##pkg##_##T},
static const struct entry types[] = {
#include "lcm_echo_types.inc"
};
#undef HORUS_LCM_TYPE

static size_t prefix_len;

static void on_message(const lcm_recv_buf_t *rb, const char *channel, void *user) {
  (void)user;
  size_t len = strlen(channel);
  if (len > 5 && strcmp(channel + len - 5, ".echo") == 0) return; /* our own echoes come back */
  const char *type = channel + prefix_len + 1;
  for (size_t i = 0; i < sizeof(types) / sizeof(types[0]); ++i) {
    if (strcmp(types[i].name, type) != 0) continue;
    char out[128];
    snprintf(out, sizeof(out), "%s.echo", channel);
    int rc = types[i].echo(rb, out);
    if (rc != 0) {
      ++failures;
      fprintf(stderr, "lcm_echo: %s: %s\n", channel,
              rc == -1 ? "the generated decoder refused it (fingerprint or length)"
                       : rc == -2 ? "bytes left over after the generated decoder" : "encode or publish failed");
    }
    return;
  }
  fprintf(stderr, "lcm_echo: %s: no generated type named '%s'\n", channel, type);
  ++failures;
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: lcm_echo <prefix> <seconds>\n");
    return 2;
  }
  const char *url = getenv("HORUS_LCM_URL");
  lcm = lcm_create(url);
  if (!lcm || lcm_get_fileno(lcm) < 0) {
    fprintf(stderr, "lcm_echo: cannot start LCM on %s\n", url ? url : "the default URL");
    return 3;
  }
  /* Subscriptions are regular expressions: escape the prefix's dots. */
  const char *prefix = argv[1];
  prefix_len = strlen(prefix);
  char regex[256];
  size_t k = 0;
  for (size_t i = 0; i < prefix_len && k + 3 < sizeof(regex); ++i) {
    if (strchr(".[]()*+?{}|^$\\", prefix[i])) regex[k++] = '\\';
    regex[k++] = prefix[i];
  }
  snprintf(regex + k, sizeof(regex) - k, "\\..*");
  lcm_subscription_t *sub = lcm_subscribe(lcm, regex, on_message, NULL);
  lcm_subscription_set_queue_capacity(sub, 0);
  printf("ready\n");
  fflush(stdout);
  const time_t end = time(NULL) + atoi(argv[2]);
  struct pollfd fds[2] = {{lcm_get_fileno(lcm), POLLIN, 0}, {0, POLLIN, 0}};
  while (time(NULL) < end) {
    if (poll(fds, 2, 100) <= 0) continue;
    if (fds[1].revents) {
      char c;
      if (read(0, &c, 1) <= 0) break; /* the test ended */
    }
    if (fds[0].revents & POLLIN) lcm_handle(lcm);
  }
  lcm_unsubscribe(lcm, sub);
  lcm_destroy(lcm);
  return failures == 0 ? 0 : 1;
}
