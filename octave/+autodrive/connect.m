function lc = connect(url, types_jar)
  % AUTODRIVE.CONNECT  Joins the LCM bus through LCM's Java bindings (Debian's liblcm-java):
  %   lc = autodrive.connect()            % the stack's bus: $AUTODRIVE_LCM_URL, else
  %                                        % lcm_types/channels.yaml's url_default
  %   lc = autodrive.connect(url)         % e.g. 'udpm://239.255.76.67:7667?ttl=0'
  %   lc = autodrive.connect(url, jar)    % the jar of our types ($AUTODRIVE_TYPES_JAR, else
  %                                        % build/release/lcm_types/java/autodrive_types.jar)
  % The types jar is built at build time (python -m autodrive.apis.octave --jar), never committed.
  % The UDP receive buffer is recv_buf_size=BYTES of the URL, else 4 MiB (autodrive.ros.bridge's
  % RECV_BUF_BYTES; capped by net.core.rmem_max): LCM's Java provider leaves the kernel's 208 KiB,
  % which a JVM starved of CPU for a moment overflows (every channel of the port arrives there).
  if nargin < 1 || isempty(url)
    url = getenv('AUTODRIVE_LCM_URL');
    if isempty(url)
      tok = regexp(fileread(autodrive.repo_file('lcm_types', 'channels.yaml')), 'url_default: "([^"]+)"', 'tokens', 'once');
      url = tok{1};
    end
  end
  if nargin < 2 || isempty(types_jar)
    types_jar = getenv('AUTODRIVE_TYPES_JAR');
    if isempty(types_jar)
      types_jar = autodrive.repo_file('build', 'release', 'lcm_types', 'java', 'autodrive_types.jar');
    end
  end
  lcm_jar = getenv('AUTODRIVE_LCM_JAR');
  if isempty(lcm_jar)
    lcm_jar = '/usr/share/java/lcm.jar';
  end
  if ~exist(lcm_jar, 'file')
    error('autodrive:missingJar', 'autodrive.connect: LCM''s jar %s is missing (install Debian''s liblcm-java)', lcm_jar);
  end
  if ~exist(types_jar, 'file')
    error('autodrive:missingJar', 'autodrive.connect: the jar of the AutoDRIVE types %s is missing (build it: python -m autodrive.apis.octave --jar)', types_jar);
  end
  javaaddpath(lcm_jar);
  javaaddpath(types_jar);
  urls = javaArray('java.lang.String', 1);
  urls(1) = url;
  lc.java = javaObject('lcm.lcm.LCM', urls);
  lc.url = url;
  lc.recv_buf_bytes = receive_buffer(lc.java, url);
  [lc.by_fingerprint, lc.fields, lc.setters] = type_table(types_jar);
end

function got = receive_buffer(lcm_obj, url)
  % Sets SO_RCVBUF of the UDP multicast socket of LCM's Java provider (its package-private
  % fields LCM.providers and UDPMulticastProvider.sock, by reflection: LCM 1.3.1 has no option);
  % the size the kernel granted [bytes], 0 for a provider without a socket (memq://, file://).
  tok = regexp(url, 'recv_buf_size=(\d+)', 'tokens', 'once');
  want = 4 * 1024 * 1024;
  if ~isempty(tok)
    want = str2double(tok{1});
  end
  got = 0;
  f = lcm_obj.getClass().getDeclaredField('providers');
  f.setAccessible(true);
  providers = f.get(lcm_obj);
  for i = 0:providers.size() - 1
    p = providers.get(i);
    if ~strcmp(char(p.getClass().getName()), 'lcm.lcm.UDPMulticastProvider')
      continue;
    end
    sf = p.getClass().getDeclaredField('sock');
    sf.setAccessible(true);
    sock = sf.get(p);
    sock.setReceiveBufferSize(want);
    got = double(sock.getReceiveBufferSize());
  end
end

function [by_fp, fields, setters] = type_table(jar)
  % fingerprint (hex) -> class name, class name -> its public instance fields, and class name ->
  % {java.lang.reflect.Field, its type's name} per field (autodrive.to_java's: looked up once
  % here, not per message, since each Java call from Octave costs ~0.3 ms, more under load)
  by_fp = containers.Map();
  fields = containers.Map();
  setters = containers.Map();
  jf = javaObject('java.util.jar.JarFile', jar);
  entries = jf.entries();
  while entries.hasMoreElements()
    name = char(entries.nextElement().getName());
    tok = regexp(name, '^autodrive/(\w+_t)\.class$', 'tokens', 'once');
    if isempty(tok)
      continue;
    end
    cls = ['autodrive.' tok{1}];
    obj = javaObject(cls);
    fields(cls) = instance_fields(obj);
    setters(cls) = field_setters(obj, fields(cls));
    by_fp(fingerprint(obj, fields(cls))) = cls;
  end
  jf.close();
end

function fp = fingerprint(obj, names)
  % The hex of the 8 bytes an encoded message starts with: encoded in Java, since the long
  % LCM_FINGERPRINT would pass through a double here (an empty message: strings set to '').
  for i = 1:numel(names)
    f = obj.getClass().getField(names{i});
    if strcmp(char(f.getType().getName()), 'java.lang.String')
      f.set(obj, '');
    end
  end
  bytes = javaObject('java.io.ByteArrayOutputStream');
  obj.encode(javaObject('java.io.DataOutputStream', bytes));
  data = bytes.toByteArray();
  fp = regexprep(sprintf('%02x', typecast(int8(data(1:8)), 'uint8')), '^0+', '');
end

function s = field_setters(obj, names)
  s = cell(numel(names), 2);
  for i = 1:numel(names)
    s{i, 1} = obj.getClass().getField(names{i});
    s{i, 2} = char(s{i, 1}.getType().getName());
  end
end

function names = instance_fields(obj)
  f = obj.getClass().getFields();
  names = {};
  for i = 1:numel(f)
    if ~javaMethod('isStatic', 'java.lang.reflect.Modifier', f(i).getModifiers())
      names{end + 1} = char(f(i).getName()); %#ok<AGROW>
    end
  end
end
