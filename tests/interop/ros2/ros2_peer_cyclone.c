/* ros2_peer_cyclone: what a ROS 2 node built on rmw_cyclonedds_cpp puts on the DDS wire, without
 * ROS 2: a plain Cyclone DDS C program over idlc's output of ros2_types.idl (ROS 2's type names,
 * pkg::msg::dds_::Name_), on ROS 2's topic names (rt/<name>), with ROS 2's USER_DATA on its
 * participant ("enclave=/;") and endpoints ("typehash=RIHS01_...;").
 *
 *   ros2_peer_cyclone <domain> <prefix> <seconds> <report> <hash per entry...>
 *
 * For each entry it reads rt/<prefix>/<name>, writes what it read to <report> as text (the
 * fields by name: ros2_peer_report.h) and writes the sample back on rt/<prefix>/<name>_echo. It
 * also reports the USER_DATA of every writer it matched (with its GUID) and of every participant it
 * discovered, and what other participants say of their nodes on ros_discovery_info.
 * Prints "ready" when its endpoints exist; stops when stdin closes or after <seconds>.
 * Loopback only, unicast discovery (horus's HORUS_DDS_LOCALHOST=1); with ROS2_PEER_LAN=1 (a test
 * that runs it on a namespace host) Cyclone DDS's defaults: the host's interfaces, multicast. */
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <dds/dds.h>

#include "ros2_types.h"

#define PEER_C 1
#include "ros2_peer_report.h"

struct entry {
  const char* name;
  const dds_topic_descriptor_t* desc;
  void (*report)(FILE* out, const void* sample);
  dds_entity_t reader, writer;
  dds_instance_handle_t seen[8];
  size_t n_seen;
};

static void r_twist(FILE* o, const void* p) {
  const geometry_msgs_msg_dds__Twist_* m = p;
  REPORT_TWIST(o, m->linear.x, m->linear.y, m->linear.z, m->angular.x, m->angular.y, m->angular.z);
}
static void r_scan(FILE* o, const void* p) {
  const sensor_msgs_msg_dds__LaserScan_* m = p;
  const uint32_t n = m->ranges._length;
  REPORT_SCAN(o, m->header.stamp.sec, m->header.stamp.nanosec, m->header.frame_id, m->angle_min, m->angle_max,
              m->angle_increment, m->range_min, m->range_max, n, n > 0 ? m->ranges._buffer[0] : 0.0f,
              n > 1 ? m->ranges._buffer[1] : 0.0f, n > 0 ? m->ranges._buffer[n - 1] : 0.0f);
}
static void r_image(FILE* o, const void* p) {
  const sensor_msgs_msg_dds__Image_* m = p;
  REPORT_IMAGE(o, m->header.stamp.sec, m->header.stamp.nanosec, m->header.frame_id, m->height, m->width, m->encoding,
               m->is_bigendian, m->step, m->data._length, checksum(m->data._buffer, m->data._length));
}
static void r_joints(FILE* o, const void* p) {
  const sensor_msgs_msg_dds__JointState_* m = p;
  const uint32_t n = m->name._length;
  REPORT_JOINTS(o, m->header.stamp.sec, m->header.stamp.nanosec, m->header.frame_id, n, n > 0 ? m->name._buffer[0] : "-",
                m->position._length > 0 ? m->position._buffer[0] : 0.0, m->velocity._length > 0 ? m->velocity._buffer[0] : 0.0,
                m->effort._length > 0 ? m->effort._buffer[0] : 0.0, n > 0 ? m->name._buffer[n - 1] : "-",
                m->position._length > 0 ? m->position._buffer[m->position._length - 1] : 0.0);
}
static void r_odom(FILE* o, const void* p) {
  const nav_msgs_msg_dds__Odometry_* m = p;
  const geometry_msgs_msg_dds__Pose_* q = &m->pose.pose;
  REPORT_ODOM(o, m->header.stamp.sec, m->header.stamp.nanosec, m->header.frame_id, m->child_frame_id, q->position.x,
              q->position.y, q->position.z, q->orientation.x, q->orientation.y, q->orientation.z, q->orientation.w,
              m->twist.twist.linear.x, m->twist.twist.angular.z, m->pose.covariance[0], m->pose.covariance[35],
              m->twist.covariance[7]);
}
static void r_tf(FILE* o, const void* p) {
  const tf2_msgs_msg_dds__TFMessage_* m = p;
  if (m->transforms._length == 0) {
    fprintf(o, "tf 0\n");
    return;
  }
  const geometry_msgs_msg_dds__TransformStamped_* t = &m->transforms._buffer[0];
  const geometry_msgs_msg_dds__Transform_* x = &t->transform;
  REPORT_TF(o, m->transforms._length, t->header.stamp.sec, t->header.stamp.nanosec, t->header.frame_id,
            t->child_frame_id, x->translation.x, x->translation.y, x->translation.z, x->rotation.x, x->rotation.y,
            x->rotation.z, x->rotation.w);
}

static struct entry entries[] = {
    {"cmd_vel", &geometry_msgs_msg_dds__Twist__desc, r_twist, 0, 0, {0}, 0},
    {"scan", &sensor_msgs_msg_dds__LaserScan__desc, r_scan, 0, 0, {0}, 0},
    {"image", &sensor_msgs_msg_dds__Image__desc, r_image, 0, 0, {0}, 0},
    {"joints", &sensor_msgs_msg_dds__JointState__desc, r_joints, 0, 0, {0}, 0},
    {"odom", &nav_msgs_msg_dds__Odometry__desc, r_odom, 0, 0, {0}, 0},
    {"tf", &tf2_msgs_msg_dds__TFMessage__desc, r_tf, 0, 0, {0}, 0},
};
#define N_ENTRIES (sizeof(entries) / sizeof(entries[0]))

static const char* kConfig =
    "<CycloneDDS><Domain Id=\"any\"><General>"
    "<Interfaces><NetworkInterface address=\"127.0.0.1\" multicast=\"false\"/></Interfaces>"
    "<AllowMulticast>false</AllowMulticast></General>"
    "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>40</MaxAutoParticipantIndex>"
    "<Peers><Peer Address=\"127.0.0.1\"/></Peers></Discovery>"
    "<SharedMemory><Enable>false</Enable></SharedMemory>"
    "</Domain></CycloneDDS>";

static int parent_gone(void) {
  struct pollfd p = {0, POLLIN, 0};
  char c;
  if (poll(&p, 1, 0) <= 0) return 0;
  return read(0, &c, 1) <= 0;
}

/* The USER_DATA of the writers the entry's reader matched, each once. */
static void report_matched(FILE* out, struct entry* e, const char* topic) {
  dds_instance_handle_t handles[8];
  const dds_return_t n = dds_get_matched_publications(e->reader, handles, 8);
  for (dds_return_t i = 0; i < n && i < 8; i++) {
    int known = 0;
    for (size_t k = 0; k < e->n_seen; k++) known |= e->seen[k] == handles[i];
    if (known || e->n_seen == 8) continue;
    dds_builtintopic_endpoint_t* ep = dds_get_matched_publication_data(e->reader, handles[i]);
    if (ep == NULL) continue;
    void* ud = NULL;
    size_t size = 0;
    char guid[33];
    hex16(ep->key.v, guid);
    if (dds_qget_userdata(ep->qos, &ud, &size) && ud != NULL) {
      fprintf(out, "userdata %s %s %.*s\n", topic, guid, (int)size, (const char*)ud);
      dds_free(ud);
    } else {
      fprintf(out, "userdata %s %s (none)\n", topic, guid);
    }
    dds_builtintopic_free_endpoint(ep);
    e->seen[e->n_seen++] = handles[i];
  }
}

static dds_guid_t own_guid;

/* What ros_discovery_info says: a line per node of each participant (not ours). */
static void report_graph(FILE* out, dds_entity_t reader) {
  void* samples[1] = {NULL};
  dds_sample_info_t info;
  while (dds_take(reader, samples, &info, 1, 1) > 0) {
    const rmw_dds_common_msg_dds__ParticipantEntitiesInfo_* p = samples[0];
    if (info.valid_data && memcmp(p->gid.data, &own_guid, 16) != 0) {
      char gid[33], g[33];
      hex16(p->gid.data, gid);
      for (uint32_t n = 0; n < p->node_entities_info_seq._length; n++) {
        const rmw_dds_common_msg_dds__NodeEntitiesInfo_* node = &p->node_entities_info_seq._buffer[n];
        fprintf(out, "graph %s %s %s writers", gid, node->node_namespace, node->node_name);
        for (uint32_t i = 0; i < node->writer_gid_seq._length; i++)
          fprintf(out, " %s", hex16(node->writer_gid_seq._buffer[i].data, g));
        fprintf(out, " readers");
        for (uint32_t i = 0; i < node->reader_gid_seq._length; i++)
          fprintf(out, " %s", hex16(node->reader_gid_seq._buffer[i].data, g));
        fprintf(out, "\n");
      }
    }
    dds_return_loan(reader, samples, 1);
    samples[0] = NULL;
  }
}

static void report_participants(FILE* out, dds_entity_t reader) {
  void* samples[4] = {NULL};
  dds_sample_info_t info[4];
  dds_return_t n;
  while ((n = dds_take(reader, samples, info, 4, 4)) > 0) {
    for (dds_return_t i = 0; i < n; i++) {
      if (!info[i].valid_data) continue;
      const dds_builtintopic_participant_t* p = samples[i];
      if (memcmp(&p->key, &own_guid, sizeof own_guid) == 0) continue; /* ours */
      void* ud = NULL;
      size_t size = 0;
      if (dds_qget_userdata(p->qos, &ud, &size) && ud != NULL) {
        fprintf(out, "participant %.*s\n", (int)size, (const char*)ud);
        dds_free(ud);
      }
    }
    dds_return_loan(reader, samples, n);
  }
}

int main(int argc, char** argv) {
  if (argc != 5 + (int)N_ENTRIES) {
    fprintf(stderr, "usage: ros2_peer_cyclone <domain> <prefix> <seconds> <report> <%zu type hashes>\n", N_ENTRIES);
    return 2;
  }
  const dds_domainid_t domain = (dds_domainid_t)atoi(argv[1]);
  const char* prefix = argv[2];
  const time_t end = time(NULL) + atoi(argv[3]);
  FILE* out = fopen(argv[4], "w");
  const char* lan = getenv("ROS2_PEER_LAN");
  const int on_lan = lan != NULL && strcmp(lan, "1") == 0;
  if (out == NULL || (!on_lan && dds_create_domain(domain, kConfig) < 0)) return 3;
  dds_qos_t* pq = dds_create_qos();
  dds_qset_userdata(pq, "enclave=/;", strlen("enclave=/;"));
  const dds_entity_t pp = dds_create_participant(domain, pq, NULL);
  dds_delete_qos(pq);
  if (pp < 0 || dds_get_guid(pp, &own_guid) < 0) return 3;
  const dds_entity_t parts = dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, NULL, NULL);
  /* ros_discovery_info as a ROS 2 participant reads it: reliable, transient local, keep last. */
  dds_qos_t* gq = dds_create_qos();
  dds_qset_reliability(gq, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(gq, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(gq, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t gt = dds_create_topic(pp, &rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc, "ros_discovery_info", NULL, NULL);
  const dds_entity_t graph = dds_create_reader(pp, gt, gq, NULL);
  dds_delete_qos(gq);
  if (gt < 0 || graph < 0) return 3;
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  char topics[N_ENTRIES][256];
  for (size_t i = 0; i < N_ENTRIES; i++) {
    char user_data[128];
    snprintf(user_data, sizeof user_data, "typehash=%s;", argv[5 + i]);
    /* ROS 2's default profile (reliable, volatile, keep last 10) with its USER_DATA; the echo
     * writer transient local, so that it satisfies any reader. */
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
    dds_qset_data_representation(q, 1, &xcdr1);
    dds_qset_userdata(q, user_data, strlen(user_data));
    char echo[280];
    snprintf(topics[i], sizeof topics[i], "rt/%s/%s", prefix, entries[i].name);
    snprintf(echo, sizeof echo, "%s_echo", topics[i]);
    const dds_entity_t ti = dds_create_topic(pp, entries[i].desc, topics[i], NULL, NULL);
    const dds_entity_t to = dds_create_topic(pp, entries[i].desc, echo, NULL, NULL);
    entries[i].reader = dds_create_reader(pp, ti, q, NULL);
    dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
    entries[i].writer = dds_create_writer(pp, to, q, NULL);
    dds_delete_qos(q);
    if (ti < 0 || to < 0 || entries[i].reader < 0 || entries[i].writer < 0) {
      fprintf(stderr, "ros2_peer_cyclone: cannot create the endpoints of %s\n", topics[i]);
      return 3;
    }
  }
  printf("ready\n");
  fflush(stdout);
  while (time(NULL) < end && !parent_gone()) {
    report_participants(out, parts);
    report_graph(out, graph);
    for (size_t i = 0; i < N_ENTRIES; i++) {
      report_matched(out, &entries[i], topics[i]);
      void* samples[1] = {NULL};
      dds_sample_info_t info;
      while (dds_take(entries[i].reader, samples, &info, 1, 1) > 0) {
        if (info.valid_data) {
          entries[i].report(out, samples[0]);
          dds_write(entries[i].writer, samples[0]);
        }
        dds_return_loan(entries[i].reader, samples, 1);
        samples[0] = NULL;
      }
    }
    fflush(out);
    dds_sleepfor(DDS_MSECS(2));
  }
  fclose(out);
  dds_delete(pp);
  return 0;
}
