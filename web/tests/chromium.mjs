// The headless Chromium every browser test launches: which binary (DUET_CHROMIUM, else Debian's)
// and the flags that make it run without a GPU, a display or the network.
export const kChromium = process.env.DUET_CHROMIUM || '/usr/bin/chromium';
export const kLaunchArgs = [
  '--headless',
  '--no-sandbox',
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--enable-unsafe-swiftshader', // WebGL on SwiftShader without a GPU
];
