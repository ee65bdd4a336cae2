/* cyclone_echo: a plain Cyclone DDS C program built at test time from what idlc makes of
 * horus-idlgen's .idl files (no horus code). For each type of the list it takes samples on
 * <prefix>/<Type> into the generated C struct and writes them back on <prefix>/<Type>/echo,
 * so a horus process that gets back what it sent proves both directions field for field.
 *
 *   cyclone_echo <domain> <prefix> <seconds>      prints "ready"; stops when stdin closes
 *
 * Loopback only, unicast discovery, as horus's HORUS_DDS_LOCALHOST=1. CYCLONEDDS_URI, when set,
 * is merged after that, as Cyclone merges a list of configurations: how its user adds
 * DDS-Security (the document `horus security dds-config --for cyclonedds` writes). */
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <dds/dds.h>

#include "geometry.h"
#include "input.h"
#include "navigation.h"
#include "perception.h"
#include "sensor.h"
#include "vision.h"
#include "wiretest.h"

struct entry {
  const char* name;
  const dds_topic_descriptor_t* desc;
  dds_entity_t reader, writer;
};

static struct entry entries[] = {
    {"Pose2D", &horus_msg_Pose2D_desc, 0, 0},
    {"TransformStamped", &horus_msg_TransformStamped_desc, 0, 0},
    {"Imu", &horus_msg_Imu_desc, 0, 0},
    {"LaserScan", &horus_msg_LaserScan_desc, 0, 0},
    {"BatteryState", &horus_msg_BatteryState_desc, 0, 0},
    {"JoystickInput", &horus_msg_JoystickInput_desc, 0, 0},
    {"OccupancyGrid", &horus_msg_OccupancyGrid_desc, 0, 0},
    {"Image", &horus_msg_Image_desc, 0, 0},
    {"Tensor", &horus_msg_Tensor_desc, 0, 0},
    {"All", &wiretest_All_desc, 0, 0},
    {"Keywords", &wiretest_Keywords_desc, 0, 0},
    {"Widths", &wiretest_Widths_desc, 0, 0},
};

static const char* kConfig =
    "<CycloneDDS><Domain Id=\"any\"><General>"
    "<Interfaces><NetworkInterface address=\"127.0.0.1\" multicast=\"false\"/></Interfaces>"
    "<AllowMulticast>false</AllowMulticast></General>"
    "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>"
    "<Peers><Peer Address=\"127.0.0.1\"/></Peers></Discovery>"
    "<Internal><SocketReceiveBufferSize min=\"default\" max=\"8MiB\"/></Internal>"
    "<SharedMemory><Enable>false</Enable></SharedMemory>"
    "</Domain></CycloneDDS>";

static int parent_gone(void) {
  struct pollfd p = {0, POLLIN, 0};
  char c;
  if (poll(&p, 1, 0) <= 0) return 0;
  return read(0, &c, 1) <= 0;
}

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: cyclone_echo <domain> <prefix> <seconds>\n");
    return 2;
  }
  const dds_domainid_t domain = (dds_domainid_t)atoi(argv[1]);
  const char* prefix = argv[2];
  const time_t end = time(NULL) + atoi(argv[3]);
  const char* more = getenv("CYCLONEDDS_URI");
  char* config = malloc(strlen(kConfig) + (more ? strlen(more) : 0) + 2);
  if (config == NULL) return 3;
  strcpy(config, kConfig);
  if (more && *more) {
    strcat(config, ",");
    strcat(config, more);
  }
  const dds_entity_t created = dds_create_domain(domain, config);
  free(config);
  if (created < 0) {
    fprintf(stderr, "cyclone_echo: dds_create_domain failed\n");
    return 3;
  }
  dds_entity_t pp = dds_create_participant(domain, NULL, NULL);
  if (pp < 0) {
    fprintf(stderr, "cyclone_echo: cannot create a participant: %s\n", dds_strretcode(pp));
    return 3;
  }
  /* Reader best effort (accepts any writer), writer reliable + transient local (satisfies any reader). */
  dds_qos_t* rq = dds_create_qos();
  dds_qset_reliability(rq, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(rq, DDS_HISTORY_KEEP_LAST, 16);
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(rq, 1, &xcdr1);
  dds_qos_t* wq = dds_create_qos();
  dds_qset_reliability(wq, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(wq, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(wq, DDS_HISTORY_KEEP_LAST, 16);
  dds_qset_durability_service(wq, 0, DDS_HISTORY_KEEP_LAST, 16, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED,
                              DDS_LENGTH_UNLIMITED);
  dds_qset_data_representation(wq, 1, &xcdr1);
  const size_t n = sizeof(entries) / sizeof(entries[0]);
  for (size_t i = 0; i < n; i++) {
    char in[512], out[520];
    snprintf(in, sizeof in, "%s/%s", prefix, entries[i].name);
    snprintf(out, sizeof out, "%s/echo", in);
    dds_entity_t ti = dds_create_topic(pp, entries[i].desc, in, NULL, NULL);
    dds_entity_t to = dds_create_topic(pp, entries[i].desc, out, NULL, NULL);
    entries[i].reader = dds_create_reader(pp, ti, rq, NULL);
    entries[i].writer = dds_create_writer(pp, to, wq, NULL);
    if (ti < 0 || to < 0 || entries[i].reader < 0 || entries[i].writer < 0) {
      fprintf(stderr, "cyclone_echo: cannot create the endpoints of %s: %s\n", entries[i].name,
              dds_strretcode(entries[i].reader < 0 ? entries[i].reader : entries[i].writer));
      return 3;
    }
  }
  dds_delete_qos(rq);
  dds_delete_qos(wq);
  printf("ready\n");
  fflush(stdout);
  unsigned long echoed = 0;
  while (time(NULL) < end && !parent_gone()) {
    for (size_t i = 0; i < n; i++) {
      void* samples[1] = {NULL};
      dds_sample_info_t info;
      /* A loan: the generated type's own deserializer fills the C struct. */
      while (dds_take(entries[i].reader, samples, &info, 1, 1) > 0) {
        if (info.valid_data && dds_write(entries[i].writer, samples[0]) == 0) echoed++;
        dds_return_loan(entries[i].reader, samples, 1);
        samples[0] = NULL;
      }
    }
    dds_sleepfor(DDS_MSECS(1));
  }
  fprintf(stderr, "cyclone_echo: echoed %lu samples\n", echoed);
  dds_delete(pp);
  return 0;
}
