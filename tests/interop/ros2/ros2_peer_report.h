/* The text both ROS 2 peers write of what they read (ros2_peer_cyclone.c, ros2_peer_fastdds.cpp),
 * one line per sample, fields by name in a fixed order, so that the test reads them the same way
 * whichever library built the peer: doubles with 17 significant digits, floats with 9. */
#ifndef HORUS_ROS2_PEER_REPORT_H
#define HORUS_ROS2_PEER_REPORT_H

#include <stdint.h>
#include <stddef.h>
#include <stdio.h>

/* A checksum of a byte run that sees order: sum of byte * (index % 251 + 1), mod 2^32. */
static inline uint32_t checksum(const uint8_t* p, uint32_t n) {
  uint32_t s = 0;
  for (uint32_t i = 0; i < n; i++) s += (uint32_t)p[i] * (i % 251u + 1u);
  return s;
}

/* A text field: "-" when empty (the line's fields are separated by spaces). */
static inline const char* text_or_dash(const char* s) { return s != NULL && *s != 0 ? s : "-"; }

/* 16 bytes (a GUID, a ROS 2 GID) as 32 lower-case hex digits into out[33]. */
static inline const char* hex16(const uint8_t* p, char* out) {
  static const char digits[] = "0123456789abcdef";
  for (int i = 0; i < 16; i++) {
    out[2 * i] = digits[p[i] >> 4];
    out[2 * i + 1] = digits[p[i] & 15];
  }
  out[32] = 0;
  return out;
}

#define REPORT_TWIST(o, lx, ly, lz, ax, ay, az) \
  fprintf(o, "twist %.17g %.17g %.17g %.17g %.17g %.17g\n", lx, ly, lz, ax, ay, az)
#define REPORT_SCAN(o, sec, nsec, frame, amin, amax, ainc, rmin, rmax, n, r0, r1, rlast)                            \
  fprintf(o, "scan %d %u %s %.9g %.9g %.9g %.9g %.9g %u %.9g %.9g %.9g\n", (int)(sec), (unsigned)(nsec), text_or_dash(frame),      \
          (double)(amin), (double)(amax), (double)(ainc), (double)(rmin), (double)(rmax), (unsigned)(n), (double)(r0), \
          (double)(r1), (double)(rlast))
#define REPORT_IMAGE(o, sec, nsec, frame, h, w, enc, be, step, size, sum)                                          \
  fprintf(o, "image %d %u %s %u %u %s %u %u %u %u\n", (int)(sec), (unsigned)(nsec), text_or_dash(frame), (unsigned)(h), (unsigned)(w), \
          text_or_dash(enc), (unsigned)(be), (unsigned)(step), (unsigned)(size), (unsigned)(sum))
#define REPORT_JOINTS(o, sec, nsec, frame, n, name0, pos0, vel0, eff0, name_last, pos_last)                           \
  fprintf(o, "joints %d %u %s %u %s %.17g %.17g %.17g %s %.17g\n", (int)(sec), (unsigned)(nsec), text_or_dash(frame), (unsigned)(n), \
          text_or_dash(name0), pos0, vel0, eff0, text_or_dash(name_last), pos_last)
#define REPORT_ODOM(o, sec, nsec, frame, child, px, py, pz, ox, oy, oz, ow, vx, wz, pc0, pc35, tc7)                   \
  fprintf(o, "odom %d %u %s %s %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", (int)(sec), \
          (unsigned)(nsec), text_or_dash(frame), text_or_dash(child), px, py, pz, ox, oy, oz, ow, vx, wz, pc0, pc35, tc7)
#define REPORT_TF(o, n, sec, nsec, frame, child, tx, ty, tz, rx, ry, rz, rw)                                        \
  fprintf(o, "tf %u %d %u %s %s %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", (unsigned)(n), (int)(sec),             \
          (unsigned)(nsec), text_or_dash(frame), text_or_dash(child), tx, ty, tz, rx, ry, rz, rw)

#endif
