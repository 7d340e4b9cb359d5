function key = load_key(path)
  % AUTODRIVE.LOAD_KEY  The 32-byte command key of a key file (tools/keys: 64 hex digits, mode
  % 0600). A missing file, one readable by group or others, or bad contents is an error naming
  % the file (the runtime's bridge refuses the same files).
  [info, err] = stat(path);
  if err ~= 0
    error('autodrive:badKey', '%s: command key file missing (create it with tools/keys create)', path);
  end
  if bitand(info.mode, bin2dec('000111111')) ~= 0
    error('autodrive:badKey', '%s: command key file is readable by group or others (mode %o); chmod 600 it', path, bitand(info.mode, 511));
  end
  words = strsplit(strtrim(fileread(path)));
  if numel(words) ~= 1 || numel(words{1}) ~= 64 || any(~isxdigit(words{1}))
    error('autodrive:badKey', '%s: command key file must hold 64 hex digits (32 bytes) on one line', path);
  end
  key = uint8(hex2dec(reshape(words{1}, 2, 32)'))';
end
