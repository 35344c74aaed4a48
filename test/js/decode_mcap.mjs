// Copyright 2026 squeeze_grasp_ros developers
// SPDX-License-Identifier: Apache-2.0
// Decode every message of an MCAP file the way Foxglove does (@mcap/core with CRC checks,
// @foxglove/rosmsg for the ros2msg schema, @foxglove/rosmsg2-serialization for the CDR) and
// print one JSON report: per topic the schema, message count, decoded count, first error and
// the frame ids of the first decoded message (see frameIds).
import fs from "node:fs";
import { McapStreamReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";

// Frame ids of the message's header and of the headers of the elements of its top-level arrays
// (MarkerArray.markers[]); nested headers such as a marker's texture image are not frames of it.
function frameIds(message) {
  const out = new Set();
  if (message.header) out.add(message.header.frame_id);
  for (const value of Object.values(message)) {
    if (Array.isArray(value)) {
      for (const item of value) if (item && item.header) out.add(item.header.frame_id);
    }
  }
  return [...out];
}

const reader = new McapStreamReader({
  decompressHandlers: await loadDecompressHandlers(),
  validateCrcs: true,
});
reader.append(fs.readFileSync(process.argv[2]));
const schemas = new Map();
const channels = new Map();
const report = {};
for (let record; (record = reader.nextRecord()); ) {
  if (record.type === "Schema") {
    schemas.set(record.id, record);  // repeated in the summary section: same content
  } else if (record.type === "Channel" && !channels.has(record.id)) {
    const schema = schemas.get(record.schemaId);
    const entry = { schema: schema.name, messages: 0, decoded: 0, error: null, frame_ids: [] };
    report[record.topic] = entry;
    let decoder = null;
    try {
      const text = new TextDecoder().decode(schema.data);
      decoder = new MessageReader(parse(text, { ros2: true }));
    } catch (err) {
      entry.error = `schema: ${err.message}`;
    }
    channels.set(record.id, { entry, decoder });
  } else if (record.type === "Message") {
    const { entry, decoder } = channels.get(record.channelId);
    entry.messages += 1;
    if (!decoder) continue;
    try {
      const message = decoder.readMessage(record.data);
      if (entry.decoded === 0) entry.frame_ids = frameIds(message);
      entry.decoded += 1;
    } catch (err) {
      entry.error ??= `message: ${err.message}`;
    }
  }
}
if (!reader.done()) throw new Error("truncated MCAP: the reader did not reach the footer");
console.log(JSON.stringify(report));
