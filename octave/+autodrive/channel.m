function name = channel(id, vehicle)
  % AUTODRIVE.CHANNEL  The concrete LCM channel of a channel id of lcm_types/channels.yaml (the
  % one place channel names are written), e.g. autodrive.channel('STATE', 'NIGEL1') is
  % 'NIGEL1_STATE'. An id the table does not list is an error naming it.
  table = fileread(autodrive.repo_file('lcm_types', 'channels.yaml'));
  tok = regexp(table, ['name: "([^"]+)", id: ' id '\>'], 'tokens', 'once');
  if isempty(tok)
    error('autodrive:unknownChannel', 'autodrive.channel: no channel with id ''%s'' in lcm_types/channels.yaml', id);
  end
  name = tok{1};
  if strncmp(name, '<VEH>', 5)
    if nargin < 2 || isempty(vehicle)
      error('autodrive:unknownChannel', 'autodrive.channel: channel %s needs a vehicle name', name);
    end
    name = [upper(vehicle) name(6:end)];
  end
end
