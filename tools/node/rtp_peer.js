// An independent RTP-MIDI peer for virja's tests: node-rtpmidi (npm "rtpmidi")
// invites a session host, waits for the clock sync, sends notes, says goodbye.
//
//   node tools/node/rtp_peer.js HOST PORT LOCAL_PORT PLAN.json
//
// PLAN.json: [{"after_ms": 100, "messages": [[0x99, 36, 100]], "deltas": [0]}, ...]
// Each step waits after_ms, then sends its messages in one RTP packet.  A step
// with "deltas" goes through Stream.sendMessage with those delta times (10 kHz
// ticks; running status applies); one without, through Session.sendMessage
// with a timestamp (its one-argument form is reported broken).  Each packet
// sent is printed as a JSON line {"sent_us": Unix us, "messages": [...]}.
'use strict';
const fs = require('fs');
const rtpmidi = require('rtpmidi');

rtpmidi.logger.level = 'error';
const [host, port, localPort, planPath] = process.argv.slice(2);
const plan = JSON.parse(fs.readFileSync(planPath, 'utf8'));
const session = new rtpmidi.Session(Number(localPort), 'node-peer', 'node-peer');
const deadline = setTimeout(() => {
  console.error('rtp_peer: no synchronised session after 20 s');
  process.exit(2);
}, 20000);

function synced() {
  const streams = session.getStreams();
  return streams.length > 0 && streams[0].latency !== null && streams[0].timeDifference !== null;
}

function sendStep(step) {
  const sentUs = Date.now() * 1000;
  if (step.deltas) {
    const commands = step.messages.map((m, i) => ({ deltaTime: step.deltas[i], data: Buffer.from(m) }));
    session.getStreams()[0].sendMessage({ timestamp: session.now(), commands });
  } else {
    for (const m of step.messages) {
      session.sendMessage(session.startTime + session.now(), m);
    }
  }
  console.log(JSON.stringify({ sent_us: sentUs, messages: step.messages }));
}

async function run() {
  while (!synced()) {
    await new Promise((r) => setTimeout(r, 20));
  }
  clearTimeout(deadline);
  console.log(JSON.stringify({ synced: true }));
  for (const step of plan) {
    await new Promise((r) => setTimeout(r, step.after_ms || 0));
    sendStep(step);
  }
  await new Promise((r) => setTimeout(r, 300));
  session.end(() => process.exit(0));
  setTimeout(() => process.exit(0), 2000);
}

session.on('ready', () => {
  session.connect({ address: host, port: Number(port) });
  run();
});
session.on('error', (err) => {
  console.error(`rtp_peer: ${err.message}`);
  process.exit(3);
});
session.start();
